// keyframe clip (ffmpeg command lines, clear errors, a real clip when ffmpeg exists) and keyframe export
// (files that assimp reads back with the run's vertex counts).
#include <gtest/gtest.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "core/error.h"
#include "core/mesh_sequence.h"
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

TEST(Export, ObjAndPlyPerFrameGltfOneFile) {
  testing::TempDir tmp;
  const auto run = testing::make_cloth_run(tmp.path() / "cloth", 8);
  MeshSequence body;
  body.add_mesh("torso", 3, {0, 1, 2});
  for (int f = 0; f < 6; ++f) body.add_frame({(VecX(9) << 0, 0, 0, 1, 0, 0, 0, 1 + 0.1 * f, 0).finished()});
  save_mesh_sequence(run / "meshes.bin", body);

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

  r.format = "gltf2";
  r.frame_begin = 0;
  r.frame_end = -1;
  files = export_run(r);
  ASSERT_TRUE(fs::exists(run / "export/cloth.gltf"));
  Assimp::Importer importer;
  const aiScene* s = importer.ReadFile((run / "export/cloth.gltf").string(), 0);
  ASSERT_NE(s, nullptr) << importer.GetErrorString();
  EXPECT_EQ(s->mNumMeshes, 12u);  // 6 frames x (cloth, torso)
  ASSERT_NE(s->mRootNode->FindNode("frame_0005"), nullptr);
  // No partial directory left behind.
  for (const auto& e : fs::directory_iterator(run / "export"))
    EXPECT_EQ(e.path().filename().string().find(".partial"), std::string::npos);
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
