// IC(0) in its two-halves-and-a-separator order: the split is the two grid rows where the halves meet, the
// preconditioned solve reaches the direct solve's answer, and the whole step is bit-identical on one and two
// threads.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include "scene/scene.h"
#include "sim/cloth/cloth_system.h"
#include "sim/cloth/direct_solve.h"
#include "sim/cloth/incomplete_cholesky.h"

namespace kf {
namespace {

// A of a 40x40 sheet with its bottom edge pinned, a few steps after release, as a block matrix.
struct Sheet {
  static constexpr int kSide = 40;
  ClothSystem sys;
  BlockSparse3 A;
  std::vector<char> free;

  Sheet()
      : sys(*parse_scene(R"({"cloth": {"nx": 40, "ny": 40, "origin": [-0.5, 1, -0.5], "u_axis": [1, 0, 0],
                              "v_axis": [0, 0, 1], "pins": "bottom_edge"}})",
                         "sheet.json")
                 .cloth,
            1.0 / 240) {
    VecX x, v, xn, vn;
    sys.initial_state(x, v);
    const VecX u = VecX::Zero(x.size());
    for (int n = 0; n < 20; ++n) {
      EXPECT_TRUE(sys.step(n, x, v, u, xn, vn));
      x.swap(xn);
      v.swap(vn);
    }
    sys.assemble(20, x, v);
    A = BlockSparse3::from_sparse(sys.system_matrix());
    free.assign(sys.particles(), 1);
    for (int i = 0; i < sys.particles(); ++i) free[i] = !sys.pinned(i);
  }
};

TEST(IncompleteCholesky, SplitsTheSheetAtTwoGridRowsAndSolvesAsTheDirectFactorDoes) {
  Sheet s;
  IncompleteCholesky ic;
  ic.analyse(s.A);
  // Bending springs reach two rows: the separator is two full rows of the sheet.
  EXPECT_EQ(ic.separator_size(), 2 * Sheet::kSide);
  ASSERT_TRUE(ic.factor(s.A, s.free));

  const VecX b = VecX::Random(s.A.block_rows() * 3);
  FilteredDirect direct;
  ASSERT_TRUE(direct.factor(s.A, s.free));
  VecX exact = VecX::Zero(b.size());
  ASSERT_TRUE(direct.solve(s.A, s.free, b, exact));

  FilteredPcg pcg;
  pcg.resize(s.A.block_rows(), Preconditioner::kIncompleteCholesky);
  pcg.prepare(s.A, s.free);
  ASSERT_TRUE(pcg.incomplete_cholesky());
  VecX x = VecX::Zero(b.size());
  const PcgResult res = pcg.solve(s.A, s.free, b, x, 1e-10, 1000);
  ASSERT_TRUE(res.converged);
  EXPECT_LT((x - exact).norm(), 1e-8 * exact.norm());

  // The preconditioner is a good one: far fewer iterations than block Jacobi.
  FilteredPcg jacobi;
  jacobi.resize(s.A.block_rows(), Preconditioner::kBlockJacobi);
  jacobi.prepare(s.A, s.free);
  VecX xj = VecX::Zero(b.size());
  const PcgResult rj = jacobi.solve(s.A, s.free, b, xj, 1e-10, 5000);
  EXPECT_LT(res.iterations, rj.iterations / 2) << res.iterations << " vs " << rj.iterations;
}

TEST(IncompleteCholesky, PreconditionedSolveIsBitIdenticalOnOneAndTwoThreads) {
  Sheet s;
  const VecX b = VecX::Random(s.A.block_rows() * 3);
  VecX x[2];
  for (int t = 1; t <= 2; ++t) {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, t);
    FilteredPcg pcg;
    pcg.resize(s.A.block_rows(), Preconditioner::kIncompleteCholesky);
    pcg.prepare(s.A, s.free);
    x[t - 1] = VecX::Zero(b.size());
    ASSERT_TRUE(pcg.solve(s.A, s.free, b, x[t - 1], 1e-10, 1000).converged);
  }
  EXPECT_TRUE(x[0] == x[1]);
}

}  // namespace
}  // namespace kf
