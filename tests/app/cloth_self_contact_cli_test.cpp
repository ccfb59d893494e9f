// cloth.self through the real binary: a sheet dropped on edge piles onto the ground in folds. With self
// contact its layers keep apart; without it they pass through each other (the check below fails).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"
#include "core/trajectory.h"
#include "../reliability/cli_harness.h"

namespace kf {
namespace {
namespace fs = std::filesystem;
using reliability::run_keyframe;
using reliability::TempDirTest;

class ClothSelfContactCli : public TempDirTest {};

constexpr int kN = 11;               // particles a side
constexpr double kSpacing = 0.05;    // m: the default self thickness

// A 0.5 m sheet standing on its lower edge just above the ground, leaning a little, dropped.
std::string pile_scene(const std::string& self) {
  return R"({"seed": 1, "time": {"fps": 30, "substeps": 2, "frames": 40},
  "cloth": {"nx": 11, "ny": 11, "width": 0.5, "height": 0.5, "origin": [-0.25, 0.03, 0],
            "u_axis": [1, 0, 0], "v_axis": [0, 0.96, 0.28], "imperfection": 0.003, "air_drag": 0.5,
            "colliders": [{"type": "ground", "thickness": 0.01, "friction": 0.5}])" + self + R"(}})";
}

// The smallest distance over all frames between particles at least three grid steps apart (farther than
// the self thickness at rest), and how far the sheet fell.
struct Pile {
  double closest = std::numeric_limits<double>::infinity();
  double top_drop = 0;
};

Pile measure(const fs::path& run) {
  const Trajectory t = load_trajectory(run / "trajectory.bin");
  Pile p;
  for (int f = 0; f < t.frames(); ++f) {
    const VecX& x = t.x[size_t(f)];
    for (int a = 0; a < kN * kN; ++a)
      for (int b = a + 1; b < kN * kN; ++b) {
        if (std::max(std::abs(a % kN - b % kN), std::abs(a / kN - b / kN)) < 3) continue;
        p.closest = std::min(p.closest, (x.segment<3>(3 * a) - x.segment<3>(3 * b)).norm());
      }
  }
  p.top_drop = t.x.front()[3 * (kN * kN - 1) + 1] - t.x.back()[3 * (kN * kN - 1) + 1];
  return p;
}

TEST_F(ClothSelfContactCli, ASheetPilingOnTheGroundKeepsItsLayersApartOnlyWithSelfContact) {
  write("self.json", pile_scene(R"(, "self": {"enabled": true})"));
  write("none.json", pile_scene(""));
  for (const char* name : {"self", "none"}) {
    const auto r = run_keyframe(std::string("simulate ") + name + ".json --out " + name, dir_);
    ASSERT_EQ(r.code, 0) << r.output;
  }
  const Pile self = measure(dir_ / "self"), none = measure(dir_ / "none");
  std::printf("closest non-neighbours: %.4f m with self contact, %.4f m without; the top fell %.3f m, %.3f m\n",
              self.closest, none.closest, self.top_drop, none.top_drop);
  EXPECT_GT(self.top_drop, 0.3);  // it did pile up
  EXPECT_GT(none.top_drop, 0.3);
  EXPECT_GT(self.closest, 0.4 * kSpacing);
  EXPECT_LT(none.closest, 0.2 * kSpacing);
}

TEST_F(ClothSelfContactCli, ABadSelfBlockOrOneBesideACharacterIsRefused) {
  write("bad.json", pile_scene(R"(, "self": {"thickness": 0})"));
  auto r = run_keyframe("simulate bad.json --out bad", dir_);
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_NE(r.output.find("bad.json: /cloth/self/thickness"), std::string::npos) << r.output;
  write("bad.json", pile_scene(R"(, "self": {"enabled": true, "radius": 1})"));
  r = run_keyframe("simulate bad.json --out bad", dir_);
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_NE(r.output.find("/cloth/self/radius"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
}

}  // namespace
}  // namespace kf
