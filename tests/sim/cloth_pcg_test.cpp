// The filtered PCG's preconditioners on a real cloth matrix: same answer, IC(0) in fewer iterations than
// block Jacobi, multigrid in a count that stays flat as the sheet is refined, pinned values kept.
#include <gtest/gtest.h>

#include <cstdio>

#include <tbb/global_control.h>

#include "adjoint/rollout.h"
#include "scene/scene.h"
#include "sim/cloth/cloth_system.h"
#include "sim/cloth/direct_solve.h"
#include "sim/cloth/incomplete_cholesky.h"

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
    B = BlockSparse3::from_sparse(A);
    b = VecX::Random(A.rows());
  }

  Solve solve(Preconditioner kind) {
    FilteredPcg pcg;
    pcg.resize(B.block_rows(), kind, spec.nx, spec.ny);
    pcg.prepare(B, free);
    Solve s;
    s.x = VecX::Zero(b.size());
    for (int i = 0; i < B.block_rows(); ++i)
      if (!free[i]) seg(s.x, i) = Vec3(1, 2, 3);
    s.res = pcg.solve(B, free, b, s.x, 1e-10, 5000);
    EXPECT_EQ(pcg.incomplete_cholesky(), kind == Preconditioner::kIncompleteCholesky);
    EXPECT_EQ(pcg.multigrid(), kind == Preconditioner::kMultigrid);
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

// The factor's pattern can leave blocks of A out (the cloth drops its bending springs'): the factor is then
// IC(0) of A without those blocks, and a different preconditioner from the full pattern's.
TEST_F(ClothPcg, IncompleteCholeskyOnPartOfThePatternFactorsTheMatrixWithoutTheRest) {
  const int nx = spec.nx;
  auto bending = [&](int i, int j) { return std::abs(i - j) == 2 || std::abs(i - j) == 2 * nx; };
  std::vector<char> keep(B.nonzero_blocks());
  std::vector<std::vector<int>> cols(B.block_rows());
  int dropped = 0;
  for (int i = 0; i < B.block_rows(); ++i)
    for (int s = B.row_start(i); s < B.row_start(i + 1); ++s) {
      keep[s] = !bending(i, B.col(s));
      dropped += !keep[s];
      if (keep[s]) cols[i].push_back(B.col(s));
    }
  ASSERT_GT(dropped, 0);
  BlockSparse3 without;
  without.set_pattern(cols);
  for (int i = 0; i < B.block_rows(); ++i)
    for (int s = without.row_start(i); s < without.row_start(i + 1); ++s)
      without.block(s) = B.block(B.find(i, without.col(s)));
  IncompleteCholesky part, other, full;
  part.analyse(B, keep);
  other.analyse(without);
  full.analyse(B);
  ASSERT_TRUE(part.factor(B, free) && other.factor(without, free) && full.factor(B, free));
  VecX zp = VecX::Zero(b.size()), zo = zp, zf = zp;
  part.apply(free, b, zp);
  other.apply(free, b, zo);
  full.apply(free, b, zf);
  EXPECT_LT((zp - zo).norm(), 1e-13 * zo.norm());
  EXPECT_GT((zp - zf).norm(), 1e-3 * zf.norm());
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

TEST_F(ClothPcg, MultigridSolvesTheSameSystemToTolerance) {
  const Solve mg = solve(Preconditioner::kMultigrid);
  const Solve ic = solve(Preconditioner::kIncompleteCholesky);
  ASSERT_TRUE(mg.res.converged);
  EXPECT_LT((mg.x - ic.x).norm(), 1e-7 * ic.x.norm());
  for (int i = 0; i < B.block_rows(); ++i)
    if (!free[i]) EXPECT_EQ(seg(mg.x, i), Vec3(1, 2, 3));
  const VecX r = b - A * mg.x;
  for (int i = 0; i < B.block_rows(); ++i)
    if (free[i]) EXPECT_LT(seg(r, i).norm(), 1e-8 * b.norm());
}

// A matrix that is not positive definite breaks CG; with multigrid the solve is repeated with block
// Jacobi, and the PCG says so.
TEST_F(ClothPcg, MultigridBreakdownFallsBackToBlockJacobi) {
  // 1.5x the diagonal's norm: enough to make the pair indefinite, small enough that the coarse levels
  // (which average it away) stay positive definite, so the V-cycle is built and CG breaks down.
  const double kScale = 1.5;
  FilteredPcg pcg;
  pcg.resize(B.block_rows(), Preconditioner::kMultigrid, spec.nx, spec.ny);
  const int i = B.block_rows() / 2, j = i + 1;
  ASSERT_TRUE(free[i] && free[j]);
  B.block(B.find(i, j)) = kScale * B.block(B.diag_slot(i)).norm() * Mat3::Identity();  // indefinite, diagonals intact
  B.block(B.find(j, i)) = B.block(B.find(i, j));
  pcg.prepare(B, free);
  ASSERT_TRUE(pcg.multigrid());
  VecX x = VecX::Zero(b.size());
  const PcgResult res = pcg.solve(B, free, b, x, 1e-10, 200);
  EXPECT_FALSE(pcg.multigrid());
  EXPECT_FALSE(res.converged);
  EXPECT_TRUE(x.allFinite());
}

// A hanging sheet, n x n over the same square metre (finer sheets: lighter particles, same springs, so A's
// condition number grows with n^2), stepped a frame; returns the mean PCG iterations per step. `cold`: every
// solve starts from zero (the steps are numbered 0, 2, 4, ..., which the warm start does not take for a
// sequence; the pins are static, so the numbering changes nothing else), which measures the preconditioner
// alone.
double mean_iterations(int n, const std::string& preconditioner, VecX* end = nullptr, bool cold = false) {
  const std::string text = R"({"time": {"fps": 24, "substeps": 10, "frames": 2},
    "cloth": {"nx": )" + std::to_string(n) + R"(, "ny": )" + std::to_string(n) +
                           R"(, "origin": [-0.5, 1, -0.5], "u_axis": [1, 0, 0], "v_axis": [0, 0, 1],
              "pins": "bottom_edge", "cg_preconditioner": ")" + preconditioner + R"("}})";
  const Scene scene = parse_scene(text, "sheet.json");
  ClothSystem sys(*scene.cloth, scene.time.h());
  VecX x, v, xn, vn;
  sys.initial_state(x, v);
  const VecX u = VecX::Zero(x.size());
  auto rec = sys.new_record();
  double sum = 0;
  const int steps = scene.time.steps();
  for (int k = 0; k < steps; ++k) {
    EXPECT_TRUE(sys.step(cold ? 2 * k : k, x, v, u, xn, vn, *rec));
    sum += sys.last_cg_iterations();
    x.swap(xn);
    v.swap(vn);
  }
  if (end) *end = x;
  return sum / steps;
}

TEST(ClothMultigrid, IterationsStayFlatAsTheSheetIsRefinedWhereIncompleteCholeskyGrows) {
  // 9x the particles.
  const double mg32 = mean_iterations(32, "multigrid", nullptr, true),
               mg96 = mean_iterations(96, "multigrid", nullptr, true);
  const double ic32 = mean_iterations(32, "incomplete_cholesky", nullptr, true),
               ic96 = mean_iterations(96, "incomplete_cholesky", nullptr, true);
  EXPECT_LT(mg96, 1.3 * mg32) << mg32 << " -> " << mg96;
  std::printf("cold starts: multigrid %.2f -> %.2f, IC(0) %.2f -> %.2f\n", mg32, mg96, ic32, ic96);
  EXPECT_GT(ic96, 2.0 * ic32) << ic32 << " -> " << ic96;
  EXPECT_LT(mg96, ic96);
}

TEST(ClothMultigrid, SameTrajectoryOnOneAndTwoThreads) {
  VecX one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    mean_iterations(48, "multigrid", &one);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    mean_iterations(48, "multigrid", &two);
  }
  EXPECT_TRUE(one == two);
}

TEST(ClothMultigrid, AutoPicksMultigridForLargeSheetsOnly) {
  auto describe = [](int n) {
    const Scene s = parse_scene(R"({"cloth": {"nx": )" + std::to_string(n) + R"(, "ny": )" + std::to_string(n) + "}}",
                                "c.json");
    return ClothSystem(*s.cloth, 1.0 / 60).describe();
  };
  EXPECT_NE(describe(50).find("PCG (incomplete_cholesky,"), std::string::npos) << describe(50);
  EXPECT_NE(describe(100).find("PCG (incomplete_cholesky,"), std::string::npos) << describe(100);
  EXPECT_NE(describe(128).find("PCG (multigrid,"), std::string::npos) << describe(128);
}

}  // namespace
}  // namespace kf
