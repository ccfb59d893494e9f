// A cloth's own mesh (cloth.mesh) in any format but OBJ is read by assimp in a child process, as a
// character is (core/mesh_import.h). Through the real `keyframe` binary: files that crash or abort assimp,
// a non-finite vertex, and a referenced buffer that is a FIFO or too large give exit 3 and one line naming
// the scene's field and the file, and write nothing; a well-formed PLY of quads still reads, its quads kept.
#include <sys/stat.h>

#include <cstring>
#include <limits>

#include "cli_harness.h"

namespace kf::reliability {
namespace {

const fs::path kModels = "/usr/share/assimp/models";  // Debian's assimp-testmodels

int lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

// A cloth scene whose mesh is `file`, pinned at its corner so that it simulates without a collider.
std::string mesh_cloth_scene(const std::string& file) {
  return R"({"time": {"fps": 30, "frames": 4},
  "cloth": {"mesh": {"file": ")" + file + R"("}, "mass": 0.1, "pins": {"min": [-1, -1, -1], "max": [0.01, 0.01, 0.01]}},
  "objectives": [{"type": "center_of_mass", "frame": 4, "target": [0.3, 0, 0.3]}],
  "controls": {"kind": "per_frame"}})";
}

// A glTF of one triangle whose positions are the 36 bytes of `buffer` (three float32 vectors).
const char* const kTriangleGltf = R"({"asset": {"version": "2.0"}, "buffers": [{"uri": "buffer.bin", "byteLength": 36}],
  "bufferViews": [{"buffer": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0})";

std::string float_bytes(const std::vector<float>& v) {
  std::string b(4 * v.size(), '\0');
  std::memcpy(b.data(), v.data(), b.size());
  return b;
}

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

class UntrustedClothMesh : public TempDirTest {
 protected:
  // `simulate` of a scene whose cloth.mesh is `file`: exit 3, one line naming the field and the file and
  // containing `expected`, nothing but the inputs left in the directory.
  void expect_refused(const std::string& file, const std::string& expected) {
    write("s.json", mesh_cloth_scene(file));
    const std::vector<std::string> before = list_tree(dir_);
    for (const char* command : {"simulate s.json --out run", "optimize s.json --out run", "inspect s.json"}) {
      SCOPED_TRACE(command);
      const CliResult r = run_bounded(command, dir_);
      EXPECT_EQ(r.code, 3) << r.output;
      EXPECT_EQ(lines(r.output), 1) << r.output;
      EXPECT_EQ(r.output.rfind("keyframe: error: s.json: /cloth/mesh/file: " + file + ": ", 0), 0u) << r.output;
      EXPECT_NE(r.output.find(expected), std::string::npos) << r.output;
      EXPECT_EQ(list_tree(dir_), before);
    }
  }
};

TEST_F(UntrustedClothMesh, RawWithColorThatCrashesAssimpIsExit3) {
  expect_refused((kModels / "RAW/WithColor.raw").string(),
                 kSanitized ? "assimp crashed reading it (" : "assimp crashed reading it (SIGSEGV)");
}

// The file that aborts assimp's triangulation for a character (UntrustedMesh): the cloth does not
// triangulate (its quads stay quads), so assimp reads it whole and the cut leaves no face.
TEST_F(UntrustedClothMesh, HalfTruncatedOffIsExit3) {
  const std::string whole = read_text(kModels / "OFF/formatDetection");
  ASSERT_GT(whole.size(), 100u);
  write("formatDetection", whole.substr(0, whole.size() / 2));  // no extension: assimp detects the format
  expect_refused("formatDetection", "the cloth mesh has no faces");
}

TEST_F(UntrustedClothMesh, NonFiniteVertexIsRefused) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  write("buffer.bin", float_bytes({0, 0, 0, 1, 0, 0, 0, nan, 1}));
  write("nan.gltf", kTriangleGltf);
  expect_refused("nan.gltf", "vertex 2 is not finite");
}

TEST_F(UntrustedClothMesh, ReferencedBufferThatIsAFifoIsRefusedWithoutHanging) {
  ASSERT_EQ(::mkfifo((dir_ / "buffer.bin").c_str(), 0600), 0);
  write("fifo.gltf", kTriangleGltf);
  expect_refused("fifo.gltf", "buffer.bin' (a file it reads): not a regular file");
}

TEST_F(UntrustedClothMesh, ReferencedBufferOverTheSizeCapIsRefused) {
  write("buffer.bin", "");
  fs::resize_file(dir_ / "buffer.bin", (std::uintmax_t(1) << 30) + 1);  // sparse
  write("huge.gltf", kTriangleGltf);
  expect_refused("huge.gltf", "buffer.bin' (a file it reads): larger than the 1 GiB a mesh file may be");
}

// A well-formed PLY (a 3 x 3 grid of quads) still reads through the child and simulates (its faces are
// checked in ClothMesh.APlyReadThroughTheChildKeepsItsQuads).
TEST_F(UntrustedClothMesh, AWellFormedPlyStillSimulates) {
  std::string ply = "ply\nformat ascii 1.0\nelement vertex 16\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 9\nproperty list uchar int vertex_indices\nend_header\n";
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) ply += std::to_string(0.1 * i) + " 0 " + std::to_string(0.1 * j) + "\n";
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      const int a = 4 * j + i;
      ply += "4 " + std::to_string(a) + " " + std::to_string(a + 1) + " " + std::to_string(a + 5) + " " +
             std::to_string(a + 4) + "\n";
    }
  write("grid.ply", ply);
  write("s.json", mesh_cloth_scene("grid.ply"));
  const CliResult r = run_bounded("simulate s.json --out run", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(fs::is_regular_file(dir_ / "run/trajectory.bin"));
}

}  // namespace
}  // namespace kf::reliability
