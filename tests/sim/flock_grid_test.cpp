#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <random>
#include <vector>

#include "sim/flock/flock_simd.h"
#include "sim/flock/neighbor_grid.h"

namespace kf {
namespace {

// The neighbours of i in the grid's documented order: by cell row (z), then cell column (x), then agent.
std::vector<int> brute_force(const VecX& x, int i, double radius) {
  std::vector<int> out;
  for (int j = 0; j < int(x.size() / 3); ++j)
    if (j != i && (seg(x, j) - seg(x, i)).squaredNorm() < radius * radius) out.push_back(j);
  const double inv = NeighborGrid::kReach / radius;
  auto key = [&](int j) { return std::tuple(std::floor(x[3 * j + 2] * inv), std::floor(x[3 * j] * inv), j); };
  std::sort(out.begin(), out.end(), [&](int a, int b) { return key(a) < key(b); });
  return out;
}

TEST(NeighborGrid, EqualsBruteForce) {
  std::mt19937_64 rng(5);
  NeighborGrid grid;  // reused across sizes, as the simulation does
  long total = 0;
  for (int p : {1, 2, 17, 300, 2000})
    for (double box : {0.5, 5.0, 60.0})  // dense, natural, sparse
      for (double radius : {0.7, 1.5}) {
        std::uniform_real_distribution<double> u(-box, box);
        VecX x = VecX::Zero(3 * p);
        for (int i = 0; i < p; ++i) x[3 * i] = u(rng), x[3 * i + 2] = u(rng);
        if (p > 3) {
          seg(x, 1) = seg(x, 0);                                     // coincident
          seg(x, 2) = seg(x, 0) + Vec3(radius * (1 - 1e-12), 0, 0);  // just inside
          seg(x, 3) = seg(x, 0) - Vec3(0, 0, radius);                // exactly at the cut-off: excluded
        }
        grid.build(x, radius);
        ASSERT_EQ(grid.agents(), p);
        for (int i = 0; i < p; ++i) {
          auto got = grid.neighbors(i);
          const std::vector<int> want = brute_force(x, i, radius);
          ASSERT_EQ(std::vector<int>(got.begin(), got.end()), want)
              << "p " << p << " box " << box << " radius " << radius << " agent " << i;
          total += long(want.size());
        }
      }
  EXPECT_GT(total, 10000) << "the configurations must actually have neighbours";
}

// The scan that tests eight candidates at once (AVX-512, where the processor has it) lists exactly what the
// scalar scan lists, in the same order, on crowds dense enough that runs hold many candidates, with agents
// at the cut-off and coincident ones.
TEST(NeighborGrid, EightAtATimeScanListsWhatTheScalarScanLists) {
  std::mt19937_64 rng(12);
  long total = 0;
  for (double box : {2.0, 10.0})
    for (int p : {50, 3000}) {
      std::uniform_real_distribution<double> u(-box, box);
      VecX x = VecX::Zero(3 * p);
      for (int i = 0; i < p; ++i) x[3 * i] = u(rng), x[3 * i + 2] = u(rng);
      for (int i = 0; i + 3 < p; i += 7) {
        seg(x, i + 1) = seg(x, i);
        seg(x, i + 2) = seg(x, i) + Vec3(1.5, 0, 0);  // exactly at the cut-off
        seg(x, i + 3) = seg(x, i) + Vec3(0, 0, 1.5 * (1 - 1e-15));
      }
      allow_flock_simd(false);
      NeighborGrid scalar;
      scalar.build(x, 1.5);
      allow_flock_simd(true);
      NeighborGrid simd;
      simd.build(x, 1.5);
      for (int i = 0; i < p; ++i) {
        auto a = scalar.neighbors(i), b = simd.neighbors(i);
        ASSERT_EQ(std::vector<int>(a.begin(), a.end()), std::vector<int>(b.begin(), b.end())) << "agent " << i;
        total += long(a.size());
      }
    }
  EXPECT_GT(total, 100000);
}

TEST(NeighborGrid, WrappedTableEqualsBruteForce) {
  // A line of agents far wider than the table has columns, and a few strays far off: cells share buckets
  // (rows and columns wrap), and lists keep their order.
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int p = 400;
  VecX x = VecX::Zero(3 * p);
  for (int i = 0; i < p; ++i) x[3 * i] = 1000.0 * u(rng), x[3 * i + 2] = 2.0 * u(rng);
  seg(x, 7) = Vec3(-3e5, 0, 4e5);
  seg(x, 8) = Vec3(-3e5 + 0.3, 0, 4e5 - 0.2);
  NeighborGrid grid;
  long total = 0;
  for (double radius : {0.5, 1.0, 3.0}) {
    grid.build(x, radius);
    for (int i = 0; i < p; ++i) {
      auto got = grid.neighbors(i);
      const std::vector<int> want = brute_force(x, i, radius);
      ASSERT_EQ(std::vector<int>(got.begin(), got.end()), want) << "radius " << radius << " agent " << i;
      total += long(want.size());
    }
  }
  EXPECT_GT(total, 1000);
}

TEST(NeighborGrid, FarApartAndNegativeCoordinates) {
  // Cells with huge and negative indices hash into the same small table without mixing up.
  VecX x = VecX::Zero(3 * 4);
  seg(x, 0) = Vec3(-1e7, 0, -1e7);
  seg(x, 1) = Vec3(-1e7 + 0.5, 0, -1e7);
  seg(x, 2) = Vec3(1e7, 0, 1e7);
  seg(x, 3) = Vec3(-0.1, 0, 0.1);
  NeighborGrid grid;
  grid.build(x, 1.0);
  EXPECT_EQ(std::vector<int>(grid.neighbors(0).begin(), grid.neighbors(0).end()), std::vector<int>{1});
  EXPECT_EQ(std::vector<int>(grid.neighbors(1).begin(), grid.neighbors(1).end()), std::vector<int>{0});
  EXPECT_TRUE(grid.neighbors(2).empty());
  EXPECT_TRUE(grid.neighbors(3).empty());
}

}  // namespace
}  // namespace kf
