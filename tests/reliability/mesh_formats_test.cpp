// cloth.mesh from a file assimp reads (PLY, Collada), through the real binary: the same grid written as OBJ,
// as PLY and as Collada gives the same motion (assimp may order the vertices differently, so the frames are
// compared as sets of points; it keeps coordinates in single precision, so they agree to float round-off, not
// bit for bit), and the OBJ's order is the file's.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <sstream>

#include "cli_harness.h"
#include "core/trajectory.h"

namespace kf::reliability {
namespace {

constexpr int kN = 5;  // vertices a side of the 0.6 m grid, in the x-z plane at y = 1

std::array<double, 3> vertex(int k) { return {0.15 * (k % kN), 1.0, 0.15 * (k / kN)}; }

std::vector<std::array<int, 4>> quads() {
  std::vector<std::array<int, 4>> q;
  for (int j = 0; j + 1 < kN; ++j)
    for (int i = 0; i + 1 < kN; ++i) q.push_back({j * kN + i, (j + 1) * kN + i, (j + 1) * kN + i + 1, j * kN + i + 1});
  return q;
}

std::string obj_text() {
  std::ostringstream os;
  for (int k = 0; k < kN * kN; ++k) os << "v " << vertex(k)[0] << " " << vertex(k)[1] << " " << vertex(k)[2] << "\n";
  for (const auto& q : quads()) os << "f " << q[0] + 1 << " " << q[1] + 1 << " " << q[2] + 1 << " " << q[3] + 1 << "\n";
  return os.str();
}

std::string ply_text() {
  std::ostringstream os;
  os << "ply\nformat ascii 1.0\nelement vertex " << kN * kN << "\nproperty double x\nproperty double y\nproperty double z\n"
     << "element face " << quads().size() << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (int k = 0; k < kN * kN; ++k) os << vertex(k)[0] << " " << vertex(k)[1] << " " << vertex(k)[2] << "\n";
  for (const auto& q : quads()) os << "4 " << q[0] << " " << q[1] << " " << q[2] << " " << q[3] << "\n";
  return os.str();
}

std::string collada_text() {
  std::ostringstream pos, idx;
  for (int k = 0; k < kN * kN; ++k) pos << vertex(k)[0] << " " << vertex(k)[1] << " " << vertex(k)[2] << " ";
  for (const auto& q : quads()) idx << q[0] << " " << q[1] << " " << q[2] << " " << q[3] << " ";
  std::ostringstream os;
  os << R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
 <asset><unit name="meter" meter="1"/><up_axis>Y_UP</up_axis></asset>
 <library_geometries><geometry id="sheet" name="Sheet"><mesh>
  <source id="sheet-pos"><float_array id="sheet-pos-array" count=")" << 3 * kN * kN << R"(">)" << pos.str()
     << R"(</float_array>
   <technique_common><accessor source="#sheet-pos-array" count=")" << kN * kN << R"(" stride="3">
    <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common>
  </source>
  <vertices id="sheet-vtx"><input semantic="POSITION" source="#sheet-pos"/></vertices>
  <polylist count=")" << quads().size() << R"("><input semantic="VERTEX" source="#sheet-vtx" offset="0"/>
   <vcount>)";
  for (size_t k = 0; k < quads().size(); ++k) os << "4 ";
  os << "</vcount><p>" << idx.str() << R"(</p></polylist>
 </mesh></geometry></library_geometries>
 <library_visual_scenes><visual_scene id="scene"><node id="Sheet" name="Sheet">
  <instance_geometry url="#sheet"/></node></visual_scene></library_visual_scenes>
 <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)";
  return os.str();
}

// A scene on mesh FILE: pinned along z = 0 by a box, keyframed by a box and with no imperfection (its draws go
// by particle index), so the particles' order does not matter.
std::string scene_on(const std::string& file) {
  return R"({"time": {"fps": 30, "frames": 12},
  "cloth": {"mesh": {"file": ")" + file + R"("}, "mass": 0.2, "imperfection": 0, "pins": {"min": [-1, 0, -0.01], "max": [1, 2, 0.01]}},
  "objectives": [{"type": "center_of_mass", "frame": 12, "particles": {"min": [-1, -5, 0.5], "max": [1, 5, 1]},
                  "target": [0.3, 0.6, 0.4]}],
  "controls": {"kind": "per_frame"}})";
}

// The farthest any particle of run a at frame f lies from the nearest particle of run b.
double set_distance(const Trajectory& a, const Trajectory& b, int f) {
  double worst = 0;
  for (int i = 0; i < a.particles; ++i) {
    double nearest = 1e300;
    for (int j = 0; j < b.particles; ++j) {
      double d = 0;
      for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(a.x[f][3 * i + c] - b.x[f][3 * j + c]));
      nearest = std::min(nearest, d);
    }
    worst = std::max(worst, nearest);
  }
  return worst;
}

class ClothMeshFormats : public TempDirTest {};

TEST_F(ClothMeshFormats, PlyAndColladaGiveTheObjsMotion) {
  write("sheet.obj", obj_text());
  write("sheet.ply", ply_text());
  write("sheet.dae", collada_text());
  std::vector<Trajectory> runs;
  for (const std::string format : {"obj", "ply", "dae"}) {
    write(format + ".json", scene_on("sheet." + format));
    const CliResult r = run_keyframe("simulate " + format + ".json --out run-" + format, dir_);
    ASSERT_EQ(r.code, 0) << format << ": " << r.output;
    EXPECT_NE(r.output.find("25 mesh particles"), std::string::npos) << format << ": " << r.output;
    runs.push_back(load_trajectory(dir_ / ("run-" + format) / "trajectory.bin"));
  }
  // The OBJ keeps the file's order: particle k starts at vertex k.
  for (int k = 0; k < kN * kN; ++k) EXPECT_NEAR(runs[0].x[0][3 * k + 2], vertex(k)[2], 1e-3) << k;
  const auto last = int(runs[0].x.size()) - 1;
  EXPECT_GT(set_distance(runs[0], runs[0], 0) + std::abs(runs[0].x[last][3 * (kN * kN - 1) + 1] - 1.0), 0.01)
      << "the sheet did not move";
  for (size_t r = 1; r < runs.size(); ++r) {
    ASSERT_EQ(runs[r].particles, runs[0].particles);
    for (int f : {0, 1, last}) EXPECT_LT(set_distance(runs[0], runs[r], f), 1e-6) << (r == 1 ? "ply" : "dae") << " frame " << f;
  }
  // An optimisation through the PLY reaches its keyframe as the OBJ's does.
  const CliResult opt = run_keyframe("optimize ply.json --out opt-ply", dir_);
  EXPECT_EQ(opt.code, 0) << opt.output;
}

}  // namespace
}  // namespace kf::reliability
