// Characters in any units and poses, through the real binary, with three files of Debian's
// assimp-testmodels in three formats other than .X: a static Collada figure a free sheet falls onto (no
// anchors), a Z-up Blender figure in its own units carrying a cape by anchors given in metres, Y up
// (scale and up_axis applied first), and a B3D creature at half size; and an .X walk looped.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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

class CharacterUnitsCli : public TempDirTest {};

struct Box3 {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 size() const { return hi - lo; }
};

// The body's vertices at `frame` of a run's meshes.bin (every mesh).
std::vector<Vec3> body_at(const MeshSequence& s, int frame) {
  std::vector<Vec3> out;
  for (int m = 0; m < int(s.meshes.size()); ++m) {
    const float* p = s.vertex_positions(frame, m);
    for (int v = 0; v < s.meshes[size_t(m)].vertices; ++v) out.emplace_back(p[3 * v], p[3 * v + 1], p[3 * v + 2]);
  }
  return out;
}

Box3 bounds(const std::vector<Vec3>& pts) {
  Box3 b;
  for (const Vec3& p : pts) b.lo = b.lo.cwiseMin(p), b.hi = b.hi.cwiseMax(p);
  return b;
}

// Collada/human.zae: a static figure 1.66 m tall (metres, Y up), arms out. A 0.4 m sheet held flat above
// its right shoulder, not pinned (the file has no anchors beside it), falls onto the shoulder.
TEST_F(CharacterUnitsCli, AFreeSheetFallsOntoAStaticColladaFiguresShoulder) {
  const fs::path human = kModels / "Collada/human.zae";
  ASSERT_TRUE(fs::exists(human)) << human << " missing: install Debian's assimp-testmodels (scripts/setup)";
  write("drape.json", R"({"seed": 1, "time": {"fps": 30, "substeps": 2, "frames": 30},
    "cloth": {"nx": 9, "ny": 9, "width": 0.4, "height": 0.4, "mass": 0.1, "origin": [-0.52, 1.6, -0.15],
              "u_axis": [1, 0, 0], "v_axis": [0, 0, 1]},
    "character": {"file": ")" + human.string() + R"("}})");
  const auto r = run_keyframe("simulate drape.json --out drape", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output.find("/anchors"), std::string::npos) << r.output;  // nothing pinned, nothing snapped
  const Json report = Json::parse(read_text(dir_ / "drape/report.json"));
  const Json& stats = report["run_stats"];
  EXPECT_GT(stats["body_contacts"].get<double>(), 0) << stats.dump();
  // Never much deeper than the contact thickness (0.012 m): the sheet meets the body, it does not pass.
  EXPECT_GT(stats["min_body_distance"].get<double>(), -0.02) << stats.dump();
  const Trajectory t = load_trajectory(dir_ / "drape/trajectory.bin");
  ASSERT_EQ(t.frames(), 31);
  // At frame 10 (1/3 s) a free fall from 1.6 m would have reached 1.055 m; the shoulder and arm hold the
  // sheet's highest particles up, and it slides off them later (drape-human.json steers it to stay).
  double top = -1e9;
  for (int i = 0; i < t.particles; ++i) top = std::max(top, t.x[10][3 * i + 1]);
  std::printf("human.zae drape: highest particle at frame 10 at y = %.3f m\n", top);
  EXPECT_GT(top, 1.2);
  // The static body does not move.
  const MeshSequence body = load_mesh_sequence(dir_ / "drape/meshes.bin");
  EXPECT_NEAR(bounds(body_at(body, 30)).size().y(), 1.66, 0.01);
}

// BLEND/HUMAN.blend: a Z-up figure 10.7 file units tall. scale 0.17 and up_axis "z" stand it 1.82 m tall
// along +Y; anchors stated in metres, Y up, at two of its vertices there, hold a cape's top edge exactly; an
// anchor 6 cm off the body is snapped to it with a warning.
TEST_F(CharacterUnitsCli, AZUpBlenderFigureInItsOwnUnitsCarriesACapeByAnchorsInMetres) {
  const fs::path file = kModels / "BLEND/HUMAN.blend";
  ASSERT_TRUE(fs::exists(file)) << file;
  const std::string character = R"("file": ")" + file.string() + R"(", "scale": 0.17, "up_axis": "z",
                                   "offset": [0, 0.9, 0])";
  write("stand.json", R"({"time": {"fps": 30, "frames": 2}, "cloth": {"nx": 3, "ny": 3, "origin": [3, 0, 0]},
    "character": {)" + character + R"(, "anchors": "none"}})");
  const auto r = run_keyframe("simulate stand.json --out stand", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  const std::vector<Vec3> body = body_at(load_mesh_sequence(dir_ / "stand/meshes.bin"), 0);
  const Box3 b = bounds(body);
  // File z (-5.196 to 5.523) is up; file y (-0.7525 to 0.8247) becomes -z.
  EXPECT_NEAR(b.size().y(), 0.17 * 10.719, 1e-3);
  EXPECT_NEAR(b.lo.y(), 0.9 - 0.17 * 5.196, 1e-3);
  EXPECT_NEAR(b.size().x(), 0.17 * 4.69, 1e-3);
  EXPECT_NEAR(b.lo.z(), -0.17 * 0.8247, 1e-3);
  // Two vertices of the upper back, one each side (metres, Y up, before the offset).
  Vec3 anchor[2];
  for (int side = 0; side < 2; ++side) {
    const Vec3 want(side ? 0.2 : -0.2, b.lo.y() + 0.8 * b.size().y(), b.lo.z());
    double best = 1e9;
    for (const Vec3& v : body)
      if ((v - want).norm() < best) best = (v - want).norm(), anchor[side] = v - Vec3(0, 0.9, 0);
  }
  const auto points = [&](const Vec3& a0, const Vec3& a1) {
    char s[256];
    std::snprintf(s, sizeof s, R"({"points": [[%.9g, %.9g, %.9g], [%.9g, %.9g, %.9g]]})", a0.x(), a0.y(), a0.z(),
                  a1.x(), a1.y(), a1.z());
    return std::string(s);
  };
  write("cape.json", R"({"time": {"fps": 30, "frames": 3}, "cloth": {"nx": 5, "ny": 5, "width": 0.4, "height": 0.5,
    "origin": [-0.2, 0.4, -0.3]}, "character": {)" + character + R"(, "anchors": )" + points(anchor[0], anchor[1]) + "}}");
  const auto c = run_keyframe("simulate cape.json --out cape", dir_);
  ASSERT_EQ(c.code, 0) << c.output;
  EXPECT_EQ(c.output.find("nearest vertex"), std::string::npos) << c.output;
  const Trajectory t = load_trajectory(dir_ / "cape/trajectory.bin");
  // The top edge's ends (particles 20 and 24) sit on the anchors, offset into the world.
  EXPECT_LT((t.x[1].segment<3>(3 * 20) - (anchor[0] + Vec3(0, 0.9, 0))).norm(), 1e-6);
  EXPECT_LT((t.x[1].segment<3>(3 * 24) - (anchor[1] + Vec3(0, 0.9, 0))).norm(), 1e-6);

  write("off.json", R"({"time": {"fps": 30, "frames": 3}, "cloth": {"nx": 5, "ny": 5, "width": 0.4, "height": 0.5,
    "origin": [-0.2, 0.4, -0.3]}, "character": {)" + character + R"(, "anchors": )" +
                        points(anchor[0] - Vec3(0, 0, 0.06), anchor[1]) + "}}");
  const auto off = run_keyframe("simulate off.json --out off", dir_);
  ASSERT_EQ(off.code, 0) << off.output;
  EXPECT_NE(off.output.find("/character/anchors: anchor 0 is 0.0"), std::string::npos) << off.output;
}

// B3D/WusonBlitz.b3d, a static creature 1.52 m tall and 3.24 m long, at half size (scale 0.5); and the walk
// of X/Testwuson.X (3.6 s) looped: with "time" playing two walks over 40 frames, frame 25 shows frame 5's
// pose again, where a held clip stands still from frame 20 on (and the warning says so).
TEST_F(CharacterUnitsCli, AB3dCreatureScalesAndAShortClipLoopsWhenAsked) {
  const fs::path b3d = kModels / "B3D/WusonBlitz.b3d", walk = kModels / "X/Testwuson.X";
  ASSERT_TRUE(fs::exists(b3d) && fs::exists(walk));
  write("half.json", R"({"time": {"fps": 30, "frames": 2}, "cloth": {"nx": 3, "ny": 3, "origin": [3, 0, 0]},
    "character": {"file": ")" + b3d.string() + R"(", "scale": 0.5}})");
  const auto r = run_keyframe("simulate half.json --out half", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  const Box3 b = bounds(body_at(load_mesh_sequence(dir_ / "half/meshes.bin"), 1));
  EXPECT_NEAR(b.size().x(), 0.5 * 0.92, 1e-3);
  EXPECT_NEAR(b.size().y(), 0.5 * 1.5156, 1e-3);
  EXPECT_NEAR(b.size().z(), 0.5 * 3.244, 1e-3);

  const auto scene = [&](const char* loop) {
    return R"({"time": {"fps": 30, "frames": 40}, "cloth": {"nx": 3, "ny": 3, "origin": [3, 0, 0]},
      "character": {"file": ")" + walk.string() + R"(", "animation": 1, "time": [[0, 0], [40, 7.2]],
                    "anchors": "none", "loop": )" + loop + "}}";
  };
  write("loop.json", scene("true"));
  write("hold.json", scene("false"));
  const auto l = run_keyframe("simulate loop.json --out loop", dir_);
  ASSERT_EQ(l.code, 0) << l.output;
  EXPECT_EQ(l.output.find("ends at"), std::string::npos) << l.output;
  const auto h = run_keyframe("simulate hold.json --out hold", dir_);
  ASSERT_EQ(h.code, 0) << h.output;
  EXPECT_NE(h.output.find("ends at 3.6 s"), std::string::npos) << h.output;
  const MeshSequence loop = load_mesh_sequence(dir_ / "loop/meshes.bin");
  const MeshSequence hold = load_mesh_sequence(dir_ / "hold/meshes.bin");
  const auto gap = [](const std::vector<Vec3>& a, const std::vector<Vec3>& c) {
    double worst = 0;
    for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, (a[i] - c[i]).norm());
    return worst;
  };
  EXPECT_GT(gap(body_at(loop, 5), body_at(loop, 15)), 0.01);  // the walk moves the body
  EXPECT_LT(gap(body_at(loop, 5), body_at(loop, 25)), 1e-5);  // and plays again
  EXPECT_GT(gap(body_at(hold, 5), body_at(hold, 25)), 0.01);
  EXPECT_LT(gap(body_at(hold, 25), body_at(hold, 35)), 1e-6);  // held
}

// Bad units and axes are refused in one line naming the key.
TEST_F(CharacterUnitsCli, ABadScaleOrUpAxisIsRefused) {
  const fs::path file = kModels / "Collada/human.zae";
  for (const auto& [key, pointer] : {std::pair<std::string, std::string>{R"("scale": 0)", "/character/scale"},
                                     {R"("up_axis": "w")", "/character/up_axis"},
                                     {R"("anchors": "shoulders")", "/character/anchors"},
                                     {R"("loop": 1)", "/character/loop"}}) {
    write("bad.json", R"({"time": {"frames": 2}, "cloth": {"nx": 3, "ny": 3},
      "character": {"file": ")" + file.string() + R"(", )" + key + "}}");
    const auto r = run_keyframe("simulate bad.json --out bad", dir_);
    EXPECT_EQ(r.code, 3) << key << "\n" << r.output;
    EXPECT_NE(r.output.find("bad.json: " + pointer), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "bad"));
  }
}

}  // namespace
}  // namespace kf
