// Mesh files that crash, abort or hang assimp, or hold non-finite numbers, through the real `keyframe`
// binary: `inspect FILE` and a scene's `character.file` both give exit 3 and one line naming the file
// (and, in a scene, the field), and write nothing.
#include <sys/stat.h>

#include <limits>

#include "cli_harness.h"

namespace kf::reliability {
namespace {

const fs::path kModels = "/usr/share/assimp/models";  // Debian's assimp-testmodels

int lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

// A cloth scene whose character is `file` (the anchors are looked for only after it is read).
std::string cape_scene(const std::string& file) {
  return R"({"time": {"fps": 30, "frames": 4},
  "cloth": {"nx": 4, "ny": 4, "width": 0.6, "height": 0.8, "origin": [-0.3, 1.2, -0.2],
            "u_axis": [1, 0, 0], "v_axis": [0, 0, 1]},
  "character": {"file": ")" + file + R"(", "anchors": {"nodes": ["Root", "Hips"]}},
  "objectives": [{"type": "center_of_mass", "frame": 4, "target": [0, 0.9, 0.3]}]})";
}

// How a crash of assimp's child shows: the signal that ended it. Under AddressSanitizer the child's heap is
// ASan's, so what an out-of-bounds write in (uninstrumented) assimp does differs: only the prefix is checked.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
std::string crashed(const std::string& signal) {
  return kSanitized ? "assimp crashed reading it (" : "assimp crashed reading it (" + signal + ")";
}

class UntrustedMesh : public TempDirTest {
 protected:
  // `inspect FILE` and `simulate` of a scene naming FILE as its character: exit 3, one line each, each
  // containing `expected` after the file's name, and nothing but the inputs left in the directory.
  void expect_refused(const std::string& file, const std::string& expected) {
    const std::vector<std::string> before = list_tree(dir_);
    const CliResult inspect = run_bounded("inspect '" + file + "'", dir_);
    EXPECT_EQ(inspect.code, 3) << inspect.output;
    EXPECT_EQ(lines(inspect.output), 1) << inspect.output;
    EXPECT_EQ(inspect.output.rfind("keyframe: error: " + file + ": " + expected, 0), 0u) << inspect.output;

    write("s.json", cape_scene(file));
    const CliResult sim = run_bounded("simulate s.json --out run", dir_);
    EXPECT_EQ(sim.code, 3) << sim.output;
    EXPECT_EQ(lines(sim.output), 1) << sim.output;
    EXPECT_EQ(sim.output.rfind("keyframe: error: s.json: /character/file: " + file + ": " + expected, 0), 0u)
        << sim.output;
    fs::remove(dir_ / "s.json");
    EXPECT_EQ(list_tree(dir_), before);
  }
};

TEST_F(UntrustedMesh, RawWithColorThatCrashesAssimpIsExit3) {
  expect_refused((kModels / "RAW/WithColor.raw").string(), crashed("SIGSEGV"));
}

TEST_F(UntrustedMesh, RawWithTextureThatCrashesAssimpIsExit3) {
  expect_refused((kModels / "RAW/WithTexture.raw").string(), crashed("SIGSEGV"));
}

TEST_F(UntrustedMesh, HalfTruncatedOffThatFailsAnAssertionIsExit3) {
  const std::string whole = read_text(kModels / "OFF/formatDetection");
  ASSERT_GT(whole.size(), 100u);
  write("formatDetection", whole.substr(0, whole.size() / 2));
  expect_refused((dir_ / "formatDetection").string(), crashed("SIGABRT"));
}

TEST_F(UntrustedMesh, CsmWithLargeFrameNumbersThatCorruptsTheHeapIsExit3) {
  write("big.csm",
        "$FirstFrame 1\n$LastFrame 2\n$Rate 120.000\n\n$Order\nA B \n\n$Points\n1  1 2 3  4 5 6  \n"
        "2147483647  1 2 3  4 5 6  \n");
  // The corrupted heap ends the child by SIGSEGV or SIGABRT, depending on what the corruption hit.
  if (!kSanitized) return expect_refused((dir_ / "big.csm").string(), "assimp crashed reading it (SIG");
  // AddressSanitizer's allocator may let assimp's out-of-bounds write pass: keyframe must survive it.
  const CliResult r = run_bounded("inspect big.csm", dir_);
  EXPECT_TRUE(r.code == 0 || r.code == 3) << r.output;
}

TEST_F(UntrustedMesh, ObjWithANanVertexIsRefused) {
  write("nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_refused((dir_ / "nan.obj").string(), "mesh 0 'defaultobject': vertex 0 is not finite");
}

// assimp's JoinIdenticalVertices welds a NaN vertex into another one: the values are checked as read.
TEST_F(UntrustedMesh, GltfWithANanVertexIsRefusedBeforeItsVerticesAreWelded) {
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, std::numeric_limits<float>::quiet_NaN(), 1};
  write("buffer.bin", std::string(reinterpret_cast<const char*>(v), sizeof v));
  write("nan.gltf", R"({"asset": {"version": "2.0"}, "buffers": [{"uri": "buffer.bin", "byteLength": 36}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0})");
  const CliResult r = run_bounded("inspect nan.gltf", dir_);
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_EQ(r.output, "keyframe: error: nan.gltf: mesh 0 'meshes[0]': vertex 2 is not finite\n");
}

TEST_F(UntrustedMesh, GltfWhoseBufferIsAFifoIsRefusedWithoutHanging) {
  ASSERT_EQ(::mkfifo((dir_ / "buffer.bin").c_str(), 0600), 0);
  write("fifo.gltf", R"({"asset": {"version": "2.0"}, "buffers": [{"uri": "buffer.bin", "byteLength": 36}],
    "bufferViews": [{"buffer": 0, "byteLength": 36}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0})");
  const CliResult r = run_bounded("inspect fifo.gltf", dir_);
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_EQ(lines(r.output), 1) << r.output;
  EXPECT_EQ(r.output.rfind("keyframe: error: fifo.gltf: '", 0), 0u) << r.output;
  EXPECT_NE(r.output.find("buffer.bin' (a file it reads): not a regular file\n"), std::string::npos) << r.output;
}

TEST_F(UntrustedMesh, FifoDeviceAndOversizedFilesAreRefusedBeforeReading) {
  ASSERT_EQ(::mkfifo((dir_ / "pipe.obj").c_str(), 0600), 0);
  fs::resize_file((write("huge.obj", ""), dir_ / "huge.obj"), (std::uintmax_t(1) << 30) + 1);  // sparse
  for (const auto& [file, expected] : std::vector<std::pair<std::string, std::string>>{
           {"pipe.obj", "not a regular file"},
           {"/dev/zero", "not a regular file"},
           {"huge.obj", "larger than the 1 GiB a mesh file may be"}}) {
    const CliResult r = run_bounded("inspect " + file, dir_);
    EXPECT_EQ(r.code, 3) << r.output;
    EXPECT_EQ(r.output, "keyframe: error: " + file + ": " + expected + "\n");
  }
}

TEST_F(UntrustedMesh, ControlBytesInTheFileNameAreEscaped) {
  write("a\x1b[31mb.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const CliResult r = run_bounded("inspect \"$(printf 'a\\033[31mb.obj')\"", dir_);
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_EQ(r.output.rfind("keyframe: error: a\\x1b[31mb.obj: mesh 0", 0), 0u) << r.output;
}

TEST_F(UntrustedMesh, TheCharacterModelsStillRead) {
  const CliResult r = run_bounded("inspect --json " + (kModels / "X/Testwuson.X").string(), dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("\"vertices\""), std::string::npos);
}

}  // namespace
}  // namespace kf::reliability
