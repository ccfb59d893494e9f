// The two axes of a control kind (scene/control_kind.h) and each basis (opt/control_basis.h): collect is the
// transpose of spread, fit recovers what spread gave, and Controls follows the kind's timing.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <string>

#include "opt/control_basis.h"
#include "opt/controls.h"

namespace kf {
namespace {

TEST(ControlKindAxes, EveryKindIsOneTimingAndOneBasis) {
  struct Row {
    ControlKind kind;
    ControlTiming timing;
    ControlBasis basis;
  };
  for (const Row& r : {Row{ControlKind::kPerStep, ControlTiming::kPerStep, ControlBasis::kPerParticle},
                       Row{ControlKind::kPerFrame, ControlTiming::kPerFrame, ControlBasis::kPerParticle},
                       Row{ControlKind::kPerFrameLattice, ControlTiming::kPerFrame, ControlBasis::kLattice},
                       Row{ControlKind::kInitialVelocity, ControlTiming::kInitial, ControlBasis::kPerParticle},
                       Row{ControlKind::kInitialLatticeVelocity, ControlTiming::kInitial, ControlBasis::kLattice},
                       Row{ControlKind::kInitialRigidVelocity, ControlTiming::kInitial, ControlBasis::kRigid}}) {
    SCOPED_TRACE(control_kind_name(r.kind));
    EXPECT_EQ(control_timing(r.kind), r.timing);
    EXPECT_EQ(control_basis(r.kind), r.basis);
  }
}

// A crumpled 5 x 4 sheet: rest positions off a plane so the lattice's axes are its widest extent.
VecX crumpled_sheet(int nx, int ny) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  VecX x(3 * nx * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) x.segment<3>(3 * (j * nx + i)) = Vec3(0.1 * i, jitter(rng), 0.12 * j + jitter(rng));
  return x;
}

VecX random_vector(long n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> N;
  VecX v(n);
  for (long k = 0; k < n; ++k) v[k] = N(rng);
  return v;
}

class EachBasis : public ::testing::TestWithParam<std::pair<ControlBasis, bool>> {};

TEST_P(EachBasis, CollectIsTheTransposeOfSpreadAndTouchesOnlyControlledComponents) {
  const auto [which, planar] = GetParam();
  const int p = 20;
  const std::vector<int> comps = planar ? std::vector<int>{0, 2} : std::vector<int>{0, 1, 2};
  const AnyControlBasis basis = make_control_basis(which, p, comps, crumpled_sheet(5, 4));
  std::visit(
      [&](const auto& b) {
        const VecX z = random_vector(b.size(), 1), y = random_vector(3 * p, 2);
        VecX spread = VecX::Zero(3 * p), collected = VecX::Zero(b.size());
        b.spread(z.data(), spread);
        b.collect(y, collected.data());
        EXPECT_GT(spread.norm(), 0);
        // <W z, y> = <z, W^T y>, to round-off.
        EXPECT_NEAR(spread.dot(y), z.dot(collected), 1e-12 * (1 + std::abs(spread.dot(y))));
        if (planar)
          for (int i = 0; i < p; ++i) EXPECT_EQ(spread[3 * i + 1], 0.0);
      },
      basis);
}

TEST_P(EachBasis, FitRecoversWhatSpreadGaveOrIsRefusedForARigidMotion) {
  const auto [which, planar] = GetParam();
  const int p = 20;
  const std::vector<int> comps = planar ? std::vector<int>{0, 2} : std::vector<int>{0, 1, 2};
  const AnyControlBasis basis = make_control_basis(which, p, comps, crumpled_sheet(5, 4));
  std::visit(
      [&](const auto& b) {
        const VecX z = random_vector(b.size(), 3);
        VecX spread = VecX::Zero(3 * p), fitted(b.size());
        b.spread(z.data(), spread);
        if (which == ControlBasis::kRigid) {
          EXPECT_THROW(b.fit(spread, fitted.data()), std::logic_error);
          return;
        }
        b.fit(spread, fitted.data());
        EXPECT_LT((fitted - z).norm(), 1e-8 * z.norm());
      },
      basis);
}

std::string basis_name(const ::testing::TestParamInfo<std::pair<ControlBasis, bool>>& info) {
  const char* const names[] = {"particle", "lattice", "rigid"};
  return std::string(names[int(info.param.first)]) + (info.param.second ? "_planar" : "");
}

INSTANTIATE_TEST_SUITE_P(Bases, EachBasis,
                         ::testing::Values(std::pair{ControlBasis::kPerParticle, false},
                                           std::pair{ControlBasis::kPerParticle, true},
                                           std::pair{ControlBasis::kLattice, false},
                                           std::pair{ControlBasis::kLattice, true},
                                           std::pair{ControlBasis::kRigid, false},
                                           std::pair{ControlBasis::kRigid, true}),
                         basis_name);

// Controls: the size is blocks × the basis' size, blocks from the timing.
TEST(ControlsAxes, SizeIsTheTimingsBlocksTimesTheBasisSize) {
  const int p = 20;
  const VecX x0 = crumpled_sheet(5, 4), v0 = VecX::Zero(3 * p);
  TimeSpec time;
  time.fps = 30, time.frames = 10, time.substeps = 2;
  auto size_of = [&](ControlKind kind) {
    ControlSpec spec;
    spec.kind = kind;
    spec.from_frame = 4;
    return Controls(spec, time, p, false, x0, v0).size();
  };
  EXPECT_EQ(size_of(ControlKind::kPerStep), (20 - 8) * 3 * p);
  EXPECT_EQ(size_of(ControlKind::kPerFrame), (10 - 4) * 3 * p);
  EXPECT_EQ(size_of(ControlKind::kPerFrameLattice), (10 - 4) * 27);
  EXPECT_EQ(size_of(ControlKind::kInitialVelocity), 3 * p);
  EXPECT_EQ(size_of(ControlKind::kInitialLatticeVelocity), 27);
  EXPECT_EQ(size_of(ControlKind::kInitialRigidVelocity), 6);
}

}  // namespace
}  // namespace kf
