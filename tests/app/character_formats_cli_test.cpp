// Characters from an SMD (Z up, with an optional companion file it probes for) and a boned Blender FBX in
// centimetres, through the real binary: `inspect` reads them and prints the height a scene gets, a scene
// with `up_axis` "z" stands the SMD upright and a sheet dropped on it lands, and `scale` 0.01 gives the FBX
// the height in metres that `inspect` printed.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "core/mesh_sequence.h"
#include "core/trajectory.h"
#include "../support/cli_test.h"

namespace kf {
namespace {
using namespace cli_test;

const fs::path kModels = "/usr/share/assimp/models";  // Debian's assimp-testmodels (scripts/setup)

class CharacterFormatsCli : public TempDirTest {};

// The body's box at `frame` of a run's meshes.bin (every mesh): lo, hi.
std::pair<Vec3, Vec3> body_box(const fs::path& meshes, int frame) {
  const MeshSequence s = load_mesh_sequence(meshes);
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (int m = 0; m < int(s.meshes.size()); ++m) {
    const float* p = s.vertex_positions(frame, m);
    for (int v = 0; v < s.meshes[size_t(m)].vertices; ++v) {
      const Vec3 x(p[3 * v], p[3 * v + 1], p[3 * v + 2]);
      lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
    }
  }
  return {lo, hi};
}

// WusonSMD.smd has no WusonSMD_animation.txt beside it: assimp's probe for it finds nothing and the file
// reads. Its creature is 1.516 file units tall along Z, 3.244 long along Y.
TEST_F(CharacterFormatsCli, InspectReadsTheSmdWithoutItsOptionalAnimationList) {
  const fs::path smd = kModels / "SMD/WusonSMD.smd";
  ASSERT_TRUE(fs::exists(smd)) << smd << " missing: install Debian's assimp-testmodels (scripts/setup)";
  ASSERT_FALSE(fs::exists(kModels / "SMD/WusonSMD_animation.txt"));
  const auto r = run_keyframe("inspect " + smd.string(), dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("height: 3.244 along Y (up_axis \"y\"), 1.516 along Z (up_axis \"z\") file units"),
            std::string::npos)
      << r.output;
  const auto j = run_keyframe("inspect --json " + smd.string(), dir_);
  ASSERT_EQ(j.code, 0) << j.output;
  const Json size = Json::parse(j.output)["bounds"]["size"];
  EXPECT_NEAR(size[2].get<double>(), 1.516, 1e-3);
}

// A companion that exists but is not a regular file stays refused: a FIFO would block the read.
TEST_F(CharacterFormatsCli, AnSmdsAnimationListThatIsAFifoIsRefused) {
  write("w.smd", read_text(kModels / "SMD/WusonSMD.smd"));
  ASSERT_EQ(::mkfifo((dir_ / "w_animation.txt").c_str(), 0600), 0);
  const auto r = run_keyframe("inspect w.smd", dir_);
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_EQ(r.output.rfind("keyframe: error: w.smd: '", 0), 0u) << r.output;
  EXPECT_NE(r.output.find("w_animation.txt' (a file it reads): not a regular file\n"), std::string::npos) << r.output;
}

// up_axis "z" stands the creature on its feet (file z is up: 1.516 m tall, its 3.244 m length along -z),
// and a free 0.6 m sheet dropped from 1.9 m lands on its back instead of falling through.
TEST_F(CharacterFormatsCli, AZUpSmdStandsUprightAndCatchesADroppedSheet) {
  const fs::path smd = kModels / "SMD/WusonSMD.smd";
  write("drop.json", R"({"seed": 1, "time": {"fps": 30, "substeps": 4, "frames": 20},
    "cloth": {"nx": 7, "ny": 7, "width": 0.6, "height": 0.6, "mass": 0.1, "origin": [-0.3, 1.9, -0.3],
              "u_axis": [1, 0, 0], "v_axis": [0, 0, 1]},
    "character": {"file": ")" + smd.string() + R"(", "up_axis": "z", "anchors": "none"}})");
  const auto r = run_keyframe("simulate drop.json --out drop", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  const auto [lo, hi] = body_box(dir_ / "drop/meshes.bin", 0);
  EXPECT_NEAR(hi.y() - lo.y(), 1.516, 1e-3);
  EXPECT_NEAR(lo.y(), -0.000566, 1e-3);  // its feet on the ground
  EXPECT_NEAR(hi.z() - lo.z(), 3.244, 1e-3);
  const Json stats = Json::parse(read_text(dir_ / "drop/report.json"))["run_stats"];
  EXPECT_GT(stats["body_contacts"].get<double>(), 0) << stats.dump();
  EXPECT_GT(stats["min_body_distance"].get<double>(), -0.02) << stats.dump();
  // Free fall would take the sheet to 1.9 - 0.5 g (2/3 s)^2 = -0.28 m by frame 20; the back holds it.
  const Trajectory t = load_trajectory(dir_ / "drop/trajectory.bin");
  double low = 1e9;
  for (int i = 0; i < t.particles; ++i) low = std::min(low, t.x[20][3 * i + 1]);
  std::printf("WusonSMD drop: lowest particle at frame 20 at y = %.3f m, body top %.3f m\n", low, hi.y());
  EXPECT_GT(low, 0.5);
}

// huesitos.fbx (Blender, centimetres): its x100 sits in its node transforms. inspect prints the height the
// posed body has, and scale 0.01 gives that many metres in a scene.
TEST_F(CharacterFormatsCli, ABonedCentimetreFbxIsAsTallInASceneAsInspectSays) {
  const fs::path fbx = kModels / "FBX/huesitos.fbx";
  ASSERT_TRUE(fs::exists(fbx));
  const auto i = run_keyframe("inspect " + fbx.string(), dir_);
  ASSERT_EQ(i.code, 0) << i.output;
  EXPECT_NE(i.output.find("units: 0.01 m each"), std::string::npos) << i.output;
  EXPECT_NE(i.output.find("height: 543.8 along Y (up_axis \"y\")"), std::string::npos) << i.output;
  EXPECT_NE(i.output.find("at its stated units (scale 0.01) 5.438 m"), std::string::npos) << i.output;
  write("cm.json", R"({"time": {"fps": 30, "frames": 2}, "cloth": {"nx": 3, "ny": 3, "origin": [30, 0, 0]},
    "character": {"file": ")" + fbx.string() + R"(", "scale": 0.01, "anchors": "none"}})");
  const auto r = run_keyframe("simulate cm.json --out cm", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  const auto [lo, hi] = body_box(dir_ / "cm/meshes.bin", 0);
  EXPECT_NEAR(hi.y() - lo.y(), 5.438, 0.01 * 5.438);
}

}  // namespace
}  // namespace kf
