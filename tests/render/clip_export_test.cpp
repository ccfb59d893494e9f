// keyframe clip (ffmpeg command lines, clear errors, a real clip when ffmpeg exists) and keyframe export
// (files that assimp reads back with the run's vertex counts).
#include <gtest/gtest.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/mesh_sequence.h"
#include "core/trajectory.h"
#include "render/clip/make_clip.h"
#include "render/export/export_run.h"
#include "render/render_run.h"
#include "synthetic_runs.h"

namespace kf::render {
namespace {

namespace fs = std::filesystem;

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& a : v) s += a + " ";
  return s;
}

TEST(Clip, CommandsAskForH264Yuv420pAndAPaletteGif) {
  ClipRequest r;
  r.gif = true;
  const auto c = clip_commands(r, "f/frame_%04d.png", 3, 30.0, {"a.mp4", "a.gif"});
  ASSERT_EQ(c.size(), 2u);
  const std::string mp4 = joined(c[0]), gif = joined(c[1]);
  for (const char* s : {"-c:v libx264", "-pix_fmt yuv420p", "-start_number 3", "-framerate 30", "a.mp4"})
    EXPECT_NE(mp4.find(s), std::string::npos) << s << " in " << mp4;
  for (const char* s : {"palettegen", "paletteuse", "-f gif", "a.gif"})
    EXPECT_NE(gif.find(s), std::string::npos) << s << " in " << gif;
}

TEST(Clip, NoFramesNamesTheRenderCommand) {
  testing::TempDir tmp;
  const auto run = testing::make_flock_run(tmp.path() / "flock");
  ClipRequest r;
  r.run_dir = run;
  try {
    make_clip(r);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("keyframe render"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(find_program("surely-not-a-program-keyframe").empty());
  EXPECT_FALSE(find_program("sh").empty());
}

// Frames in a video file as ffprobe counts them by decoding; -1 when it cannot tell.
int decoded_frames(const fs::path& video) {
  const fs::path ffprobe = find_program("ffprobe");
  if (ffprobe.empty()) return -1;
  const std::string cmd = "'" + ffprobe.string() + "' -v error -count_frames -select_streams v:0 "
                          "-show_entries stream=nb_read_frames -of csv=p=0 '" + video.string() + "'";
  FILE* p = popen(cmd.c_str(), "r");
  char buf[64] = {0};
  const size_t n = p ? fread(buf, 1, sizeof buf - 1, p) : 0;
  if (p) pclose(p);
  return n > 0 ? std::atoi(buf) : -1;
}

// scripts/setup installs ffmpeg, so CI (CI=true) must encode; elsewhere a missing ffmpeg skips.
bool ffmpeg_or_skip() {
  if (!find_program("ffmpeg").empty()) return true;
  if (std::getenv("CI")) ADD_FAILURE() << "ffmpeg not installed; scripts/setup installs it";
  return false;
}

TEST(Clip, TruncatedFrameIsRefusedBeforeEncoding) {
  // ffmpeg skips a frame it cannot decode and exits 0; the clip must not be made from a broken frame.
  testing::TempDir tmp;
  const auto run = testing::make_flock_run(tmp.path() / "flock");
  RenderRequest rr;
  rr.run_dir = run;
  rr.width = 64;
  rr.height = 48;
  ASSERT_EQ(render_run(rr), 6);
  const fs::path frame = run / "frames/frame_0003.png";
  fs::resize_file(frame, fs::file_size(frame) / 2);
  ClipRequest r;
  r.run_dir = run;
  r.ffmpeg = "/bin/true";  // never reached
  try {
    make_clip(r);
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(frame.string() + ": corrupt or truncated PNG", 0), 0u) << e.what();
  }
  EXPECT_FALSE(fs::exists(run / "clip.mp4"));
  EXPECT_FALSE(fs::exists(run / "clip.mp4.partial"));
}

TEST(Clip, EncodesFramesAndATurntableAsMp4AndGif) {
  if (!ffmpeg_or_skip()) GTEST_SKIP() << "ffmpeg not installed";
  testing::TempDir tmp;
  const auto run = testing::make_flock_run(tmp.path() / "flock");
  RenderRequest rr;
  rr.run_dir = run;
  rr.width = 65;  // odd on purpose: H.264 needs even sides
  rr.height = 48;
  EXPECT_EQ(render_run(rr), 6);
  rr.turntable = 8;
  EXPECT_EQ(render_run(rr), 8);
  ClipRequest r;
  r.run_dir = run;
  r.gif = true;
  const auto files = make_clip(r);
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(files[0], run / "clip.mp4");
  EXPECT_EQ(files[1], run / "clip.gif");
  for (const auto& f : files) EXPECT_GT(fs::file_size(f), 100u) << f;
  EXPECT_FALSE(fs::exists(run / "clip.mp4.partial"));
  r.turntable = true;
  const auto turn = make_clip(r);
  ASSERT_EQ(turn.size(), 2u);
  EXPECT_EQ(turn[0], run / "turntable.mp4");
  EXPECT_EQ(turn[1], run / "turntable.gif");
  if (!find_program("ffprobe").empty()) {
    EXPECT_EQ(decoded_frames(run / "clip.mp4"), 6);
    EXPECT_EQ(decoded_frames(run / "clip.gif"), 6);
    EXPECT_EQ(decoded_frames(run / "turntable.mp4"), 8);
    EXPECT_EQ(decoded_frames(run / "turntable.gif"), 8);
  }
}

// Vertex count of every mesh assimp finds in `file`, by mesh name.
std::map<std::string, unsigned> mesh_vertices(const fs::path& file) {
  Assimp::Importer importer;
  // OBJ and PLY readers give one vertex per face corner until identical ones are joined.
  const aiScene* s = importer.ReadFile(file.string(), aiProcess_JoinIdenticalVertices);
  EXPECT_NE(s, nullptr) << file << ": " << importer.GetErrorString();
  std::map<std::string, unsigned> out;
  if (s)
    for (unsigned k = 0; k < s->mNumMeshes; ++k) out[s->mMeshes[k]->mName.C_Str()] += s->mMeshes[k]->mNumVertices;
  return out;
}

// A run with a cloth and a moving "torso" triangle over 6 frames.
fs::path cloth_run_with_body(const fs::path& dir) {
  const auto run = testing::make_cloth_run(dir, 8);
  MeshSequence body;
  body.add_mesh("torso", 3, {0, 1, 2});
  for (int f = 0; f < 6; ++f) body.add_frame({(VecX(9) << 0, 0, 0, 1, 0, 0, 0, 1 + 0.1 * f, 0).finished()});
  save_mesh_sequence(run / "meshes.bin", body);
  return run;
}

TEST(Export, ObjAndPlyPerFrameEachObjectItsOwnGroup) {
  testing::TempDir tmp;
  const auto run = cloth_run_with_body(tmp.path() / "cloth");
  ExportRequest r;
  r.run_dir = run;
  r.format = "obj";
  auto files = export_run(r);
  EXPECT_TRUE(fs::exists(run / "export/frame_0000.obj"));
  EXPECT_TRUE(fs::exists(run / "export/frame_0005.obj"));
  EXPECT_EQ(std::count_if(files.begin(), files.end(), [](const fs::path& p) { return p.extension() == ".obj"; }), 6);
  auto v = mesh_vertices(run / "export/frame_0002.obj");
  EXPECT_EQ(v["cloth"], 64u);
  EXPECT_EQ(v["torso"], 3u);

  r.format = "ply";
  r.frame_begin = 1;
  r.frame_end = 3;
  files = export_run(r);
  EXPECT_EQ(files.size(), 2u);
  EXPECT_TRUE(fs::exists(run / "export/frame_0001.ply"));
  unsigned ply_vertices = 0;
  for (const auto& [name, n] : mesh_vertices(run / "export/frame_0001.ply")) ply_vertices += n;
  EXPECT_EQ(ply_vertices, 67u);

  // Each object is its own group, not one merged mesh per frame.
  std::ifstream obj(run / "export/frame_0002.obj");
  const std::string text((std::istreambuf_iterator<char>(obj)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\ng cloth\n"), std::string::npos);
  EXPECT_NE(text.find("\ng torso\n"), std::string::npos);
  // No partial directory left behind.
  for (const auto& e : fs::directory_iterator(run / "export"))
    EXPECT_EQ(e.path().filename().string().find(".partial"), std::string::npos);
}

// The Khronos validator's report on a .gltf (tests/render/gltf_validate.js; scripts/setup installs the
// npm package gltf-validator). Empty when node or the package is missing outside CI.
nlohmann::json validator_report(const fs::path& gltf) {
  const std::string cmd = "NODE_PATH=\"$(npm root -g 2>/dev/null)\" node '" KEYFRAME_SOURCE_DIR
                          "/tests/render/gltf_validate.js' '" + gltf.string() + "' 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  const int status = pclose(p);
  if (status != 0) {
    if (std::getenv("CI")) ADD_FAILURE() << "the glTF validator did not run (scripts/setup installs it): " << out;
    return {};
  }
  return nlohmann::json::parse(out);
}

TEST(Export, AnimatedGltfPlaysEveryFrameAndPassesTheKhronosValidator) {
  testing::TempDir tmp;
  const auto run = cloth_run_with_body(tmp.path() / "cloth");
  ExportRequest r;
  r.run_dir = run;  // gltf2 is the default format
  const auto files = export_run(r);
  ASSERT_EQ(files.size(), 2u);
  const fs::path gltf = run / "export/cloth.gltf";
  ASSERT_TRUE(fs::exists(gltf));
  ASSERT_TRUE(fs::exists(run / "export/cloth.bin"));
  std::ifstream in(gltf);
  const auto doc = nlohmann::json::parse(in);
  // Each object once, named, with one morph target per frame and one animation switching between them.
  ASSERT_EQ(doc["nodes"].size(), 2u);
  EXPECT_EQ(doc["nodes"][0]["name"], "cloth");
  EXPECT_EQ(doc["nodes"][1]["name"], "torso");
  ASSERT_EQ(doc["animations"].size(), 1u);
  const auto& anim = doc["animations"][0];
  ASSERT_EQ(anim["channels"].size(), 2u);
  EXPECT_EQ(anim["channels"][0]["target"]["path"], "weights");
  const auto& input = doc["accessors"][anim["samplers"][0]["input"].get<int>()];
  EXPECT_EQ(input["count"], 6);  // the run's frames
  EXPECT_NEAR(input["max"][0].get<double>(), 5.0 / 30.0, 1e-6);
  EXPECT_EQ(doc["meshes"][0]["primitives"][0]["targets"].size(), 6u);

  // Frame 4 of the torso: the rest position plus target 4 (read from the buffer) is the mesh sequence's.
  std::ifstream bin_in(run / "export/cloth.bin", std::ios::binary);
  const std::string bin((std::istreambuf_iterator<char>(bin_in)), std::istreambuf_iterator<char>());
  auto vertex = [&](int accessor, int i) {
    const auto& a = doc["accessors"][accessor];
    const auto& v = doc["bufferViews"][a["bufferView"].get<int>()];
    float xyz[3];
    std::memcpy(xyz, bin.data() + v["byteOffset"].get<size_t>() + 12 * size_t(i), 12);
    return Vec3(xyz[0], xyz[1], xyz[2]);
  };
  const auto& torso = doc["meshes"][1]["primitives"][0];
  const Vec3 at4 = vertex(torso["attributes"]["POSITION"], 2) + vertex(torso["targets"][4]["POSITION"], 2);
  EXPECT_LT((at4 - Vec3(0, 1.4, 0)).norm(), 1e-6);

  const auto report = validator_report(gltf);
  if (report.is_null()) GTEST_SKIP() << "node or gltf-validator not installed";
  SCOPED_TRACE(report["issues"].dump());
  EXPECT_EQ(report["issues"]["numErrors"], 0);
  EXPECT_EQ(report["issues"]["numWarnings"], 0);
  EXPECT_EQ(report["info"]["animationCount"], 1);

  // A flock's agents too.
  const auto flock = testing::make_flock_run(tmp.path() / "flock");
  r.run_dir = flock;
  export_run(r);
  const auto flock_report = validator_report(flock / "export/flock.gltf");
  EXPECT_EQ(flock_report["issues"]["numErrors"], 0) << flock_report["issues"].dump();
  EXPECT_EQ(flock_report["info"]["animationCount"], 1);
}

TEST(Export, PointCacheAndRestObjReadBackAsTheRun) {
  testing::TempDir tmp;
  const auto run = cloth_run_with_body(tmp.path() / "cloth");
  ExportRequest r;
  r.run_dir = run;
  r.format = "pc2";
  r.frame_begin = 1;
  const auto files = export_run(r);
  EXPECT_EQ(files.size(), 4u);  // cloth and torso: .obj and .pc2 each
  std::ifstream in(run / "export/cloth.pc2", std::ios::binary);
  const std::string pc2((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GE(pc2.size(), 32u);
  EXPECT_EQ(pc2.substr(0, 12), std::string("POINTCACHE2\0", 12));
  int32_t version, points, samples;
  float start, rate;
  std::memcpy(&version, pc2.data() + 12, 4);
  std::memcpy(&points, pc2.data() + 16, 4);
  std::memcpy(&start, pc2.data() + 20, 4);
  std::memcpy(&rate, pc2.data() + 24, 4);
  std::memcpy(&samples, pc2.data() + 28, 4);
  EXPECT_EQ(version, 1);
  EXPECT_EQ(points, 64);
  EXPECT_EQ(start, 1.0f);
  EXPECT_EQ(rate, 1.0f);
  EXPECT_EQ(samples, 5);  // frames 1..5
  ASSERT_EQ(pc2.size(), 32u + size_t(samples) * size_t(points) * 12u);
  // Sample 2 (frame 3), particle 10 is the trajectory's, in float.
  const Trajectory t = load_trajectory(run / "trajectory.bin");
  float xyz[3];
  std::memcpy(xyz, pc2.data() + 32 + (2 * 64 + 10) * 12, 12);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(xyz[c], float(t.x[3][3 * 10 + c]));
  // The rest OBJ: one vertex per particle, in particle order (frame 1), and the grid's triangles.
  std::ifstream obj(run / "export/cloth.obj");
  int vertices = 0, faces = 0;
  Vec3 v10;
  for (std::string line; std::getline(obj, line);) {
    if (line.rfind("v ", 0) == 0 && vertices++ == 10) std::sscanf(line.c_str(), "v %lf %lf %lf", &v10.x(), &v10.y(), &v10.z());
    faces += line.rfind("f ", 0) == 0;
  }
  EXPECT_EQ(vertices, 64);
  EXPECT_EQ(faces, 2 * 7 * 7);
  EXPECT_LT((v10 - seg(t.x[1], 10)).norm(), 1e-5);
}

TEST(Export, BadFormatAndFramesFailBeforeWriting) {
  testing::TempDir tmp;
  const auto run = testing::make_flock_run(tmp.path() / "flock");
  ExportRequest r;
  r.run_dir = run;
  r.format = "fbx";
  EXPECT_THROW(export_run(r), InputError);
  r.format = "obj";
  r.frame_begin = 9;
  EXPECT_THROW(export_run(r), InputError);
  EXPECT_FALSE(fs::exists(run / "export"));
  r.frame_begin = 0;
  r.frame_end = 1;
  export_run(r);
  EXPECT_GT(mesh_vertices(run / "export/frame_0000.obj")["agents"], 40u);
}

}  // namespace
}  // namespace kf::render
