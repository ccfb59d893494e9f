// libFuzzer target for mesh files through the isolated reader (core/mesh_import.h): any bytes, under any of a
// few file extensions (which pick assimp's importer), either give a scene whose every index is in range and
// every number finite, or an InputError. assimp's own crashes end its child process and become that
// InputError; a crash, leak or hang of this process is a finding.
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/mesh_import.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  namespace fs = std::filesystem;
  if (size == 0) return 0;
  static const char* const kExtensions[] = {".obj", ".off", ".ply", ".stl", ".gltf", ".x", ".csm", ".raw"};
  // The first byte picks the format; the rest is the file.
  const std::string ext = kExtensions[data[0] % (sizeof kExtensions / sizeof *kExtensions)];
  const fs::path file = fs::temp_directory_path() / ("keyframe_mesh_fuzz_" + std::to_string(::getpid()) + ext);
  std::ofstream(file, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data + 1), std::streamsize(size - 1));
  try {
    // A hang of assimp ends its child after 3 s, well within the fuzzer's own timeout.
    kf::MeshImportOptions options{aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_LimitBoneWeights, 4};
    options.seconds = 3;
    const auto scene = kf::import_mesh_file(file, options);
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      const aiMesh& mesh = *scene->mMeshes[m];
      for (unsigned f = 0; f < mesh.mNumFaces; ++f)
        for (unsigned k = 0; k < mesh.mFaces[f].mNumIndices; ++k)
          if (mesh.mFaces[f].mIndices[k] >= mesh.mNumVertices) __builtin_trap();
      for (unsigned v = 0; v < mesh.mNumVertices; ++v)
        if (!std::isfinite(mesh.mVertices[v].x + mesh.mVertices[v].y + mesh.mVertices[v].z)) __builtin_trap();
    }
  } catch (const kf::InputError&) {
  }
  fs::remove(file);
  return 0;
}
