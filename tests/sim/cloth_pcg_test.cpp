// The filtered PCG's two preconditioners on a real cloth matrix: same answer, IC(0) in fewer iterations,
// pinned values kept.
#include <gtest/gtest.h>

#include "scene/scene.h"
#include "sim/cloth/cloth_system.h"
#include "sim/cloth/direct_solve.h"

namespace kf {
namespace {

struct Solve {
  VecX x;
  PcgResult res;
};

// A of a 20x20 cloth with its top edge pinned, a moment after release (stretched springs, some buckled).
class ClothPcg : public ::testing::Test {
 protected:
  void SetUp() override {
    spec = *parse_scene(R"({"cloth": {"nx": 20, "ny": 20, "pins": "top_edge", "velocity": [0.3, -0.2, 1.0]}})",
                        "c.json")
                .cloth;
    ClothSystem sys(spec, 1.0 / 60);
    VecX x, v, xn, vn;
    sys.initial_state(x, v);
    const VecX u = VecX::Zero(x.size());
    xn = x;
    vn = v;
    for (int n = 0; n < 5; ++n) {
      sys.step(n, x, v, u, xn, vn);
      x = xn;
      v = vn;
    }
    sys.assemble(5, x, v);
    A = sys.system_matrix();
    // Rebuild the block matrix from the system's own (same pattern, same values).
    free.assign(sys.particles(), 1);
    for (int i = 0; i < sys.particles(); ++i) free[i] = !sys.pinned(i);
    std::vector<std::vector<int>> cols(sys.particles());
    for (int k = 0; k < A.outerSize(); ++k)
      for (SpMat::InnerIterator it(A, k); it; ++it) cols[it.row() / 3].push_back(int(it.col() / 3));
    B.set_pattern(cols);
    for (int k = 0; k < A.outerSize(); ++k)
      for (SpMat::InnerIterator it(A, k); it; ++it)
        B.block(B.find(int(it.row() / 3), int(it.col() / 3)))(it.row() % 3, it.col() % 3) = it.value();
    b = VecX::Random(A.rows());
  }

  Solve solve(Preconditioner kind) {
    FilteredPcg pcg;
    pcg.resize(B.block_rows(), kind);
    pcg.prepare(B, free);
    Solve s;
    s.x = VecX::Zero(b.size());
    for (int i = 0; i < B.block_rows(); ++i)
      if (!free[i]) seg(s.x, i) = Vec3(1, 2, 3);
    s.res = pcg.solve(B, free, b, s.x, 1e-10, 5000);
    EXPECT_EQ(pcg.incomplete_cholesky(), kind == Preconditioner::kIncompleteCholesky);
    return s;
  }

  ClothSpec spec;
  SpMat A;
  BlockSparse3 B;
  std::vector<char> free;
  VecX b;
};

TEST_F(ClothPcg, IncompleteCholeskyAgreesWithBlockJacobiInFewerIterations) {
  const Solve jac = solve(Preconditioner::kBlockJacobi);
  const Solve ic = solve(Preconditioner::kIncompleteCholesky);
  ASSERT_TRUE(jac.res.converged);
  ASSERT_TRUE(ic.res.converged);
  ASSERT_GT(ic.x.norm(), 0);
  EXPECT_LT((ic.x - jac.x).norm(), 1e-5 * jac.x.norm());
  EXPECT_LT(ic.res.iterations, jac.res.iterations / 2) << ic.res.iterations << " vs " << jac.res.iterations;
  for (int i = 0; i < B.block_rows(); ++i)
    if (!free[i]) EXPECT_EQ(seg(ic.x, i), Vec3(1, 2, 3));
  // The free rows satisfy A x = b.
  const VecX r = b - A * ic.x;
  for (int i = 0; i < B.block_rows(); ++i)
    if (free[i]) EXPECT_LT(seg(r, i).norm(), 1e-8 * b.norm());
}

TEST_F(ClothPcg, IndefinitePivotFallsBackToBlockJacobi) {
  // Make one free diagonal block indefinite: IC(0) must notice and hand over to block Jacobi.
  const int i = B.block_rows() / 2;
  ASSERT_TRUE(free[i]);
  B.block(B.diag_slot(i)) = -Mat3::Identity();
  FilteredPcg pcg;
  pcg.resize(B.block_rows(), Preconditioner::kIncompleteCholesky);
  pcg.prepare(B, free);
  EXPECT_FALSE(pcg.incomplete_cholesky());
}

// The sparse direct solve (pattern analysed once, values refreshed each factor) on the same matrix: A x = b
// on the free rows to round-off, pins kept, and a second factor of changed values solves the new system.
TEST_F(ClothPcg, DirectSolveIsExactAndReusesItsAnalysis) {
  FilteredDirect direct;
  for (int round = 0; round < 2; ++round) {
    if (round == 1)  // new values on the same pattern: the mass term doubled
      for (int i = 0; i < B.block_rows(); ++i) {
        B.block(B.diag_slot(i)) += B.block(B.diag_slot(i)).diagonal().asDiagonal();
        for (int a = 0; a < 3; ++a) A.coeffRef(3 * i + a, 3 * i + a) *= 2;
      }
    ASSERT_TRUE(direct.factor(B, free)) << FilteredDirect::backend();
    VecX x = VecX::Zero(b.size());
    for (int i = 0; i < B.block_rows(); ++i)
      if (!free[i]) seg(x, i) = Vec3(1, 2, 3);
    ASSERT_TRUE(direct.solve(B, free, b, x));
    const VecX r = b - A * x;
    for (int i = 0; i < B.block_rows(); ++i) {
      if (free[i]) EXPECT_LT(seg(r, i).norm(), 1e-12 * b.norm()) << "round " << round << ", particle " << i;
      else EXPECT_EQ(seg(x, i), Vec3(1, 2, 3));
    }
    const Solve ic = solve(Preconditioner::kIncompleteCholesky);
    EXPECT_LT((ic.x - x).norm(), 1e-7 * x.norm()) << "round " << round;
  }
}

}  // namespace
}  // namespace kf
