#include "core/mesh_sequence.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <ostream>
#include <stdexcept>

#include "core/atomic_file.h"
#include "core/error.h"

namespace kf {

namespace {
constexpr char kMagic[8] = {'K', 'F', 'M', 'E', 'S', 'H', '0', '1'};
constexpr uint32_t kMaxMeshes = 4096, kMaxName = 255, kMaxFrames = 1'000'000, kMaxVertices = 50'000'000;

template <class T>
void put(std::ostream& out, T v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof v);
}
}  // namespace

int MeshSequence::total_vertices() const {
  int n = 0;
  for (const auto& m : meshes) n += m.vertices;
  return n;
}

int MeshSequence::add_mesh(const std::string& name, int vertices, std::vector<uint32_t> triangles) {
  if (!positions.empty()) throw std::invalid_argument("mesh sequence: add meshes before frames");
  if (name.empty() || name.size() > kMaxName) throw std::invalid_argument("mesh sequence: name must be 1..255 bytes");
  if (vertices <= 0 || triangles.size() % 3 != 0)
    throw std::invalid_argument("mesh sequence: mesh \"" + name + "\" needs vertices and 3 indices per triangle");
  for (uint32_t i : triangles)
    if (i >= uint32_t(vertices))
      throw std::invalid_argument("mesh sequence: mesh \"" + name + "\" index " + std::to_string(i) +
                                  " out of range (" + std::to_string(vertices) + " vertices)");
  meshes.push_back({name, vertices, std::move(triangles)});
  return int(meshes.size()) - 1;
}

void MeshSequence::add_frame(const std::vector<VecX>& x) {
  if (x.size() != meshes.size())
    throw std::invalid_argument("mesh sequence: frame has " + std::to_string(x.size()) + " meshes, expected " +
                                std::to_string(meshes.size()));
  std::vector<float> p;
  p.reserve(3 * size_t(total_vertices()));
  for (size_t m = 0; m < meshes.size(); ++m) {
    if (x[m].size() != 3 * meshes[m].vertices)
      throw std::invalid_argument("mesh sequence: mesh \"" + meshes[m].name + "\" frame has " +
                                  std::to_string(x[m].size()) + " coordinates, expected " +
                                  std::to_string(3 * meshes[m].vertices));
    for (Eigen::Index k = 0; k < x[m].size(); ++k) p.push_back(float(x[m][k]));
  }
  positions.push_back(std::move(p));
}

const float* MeshSequence::vertex_positions(int frame, int mesh) const {
  size_t offset = 0;
  for (int m = 0; m < mesh; ++m) offset += 3 * size_t(meshes[m].vertices);
  return positions[size_t(frame)].data() + offset;
}

void save_mesh_sequence(const std::filesystem::path& path, const MeshSequence& seq) {
  const size_t floats = 3 * size_t(seq.total_vertices());
  for (const auto& f : seq.positions)
    if (f.size() != floats) throw OutputError(path.string() + ": mesh sequence frames of inconsistent size");
  write_stream_atomic(path, [&](std::ostream& out) {
    out.write(kMagic, 8);
    put(out, uint32_t(seq.meshes.size()));
    put(out, uint32_t(seq.frames()));
    put(out, double(seq.fps));
    for (const auto& m : seq.meshes) {
      put(out, uint32_t(m.name.size()));
      out.write(m.name.data(), std::streamsize(m.name.size()));
      put(out, uint32_t(m.vertices));
      put(out, uint32_t(m.triangle_count()));
      out.write(reinterpret_cast<const char*>(m.triangles.data()), std::streamsize(4 * m.triangles.size()));
    }
    for (const auto& f : seq.positions) out.write(reinterpret_cast<const char*>(f.data()), std::streamsize(4 * f.size()));
  });
}

MeshSequence load_mesh_sequence(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(file + ": cannot open mesh sequence");
  auto get = [&](auto& v, const char* what) {
    in.read(reinterpret_cast<char*>(&v), sizeof v);
    if (!in) throw InputError(file + ": truncated (while reading " + what + ")");
  };
  char magic[8] = {};
  in.read(magic, 8);
  if (!in || std::memcmp(magic, kMagic, 8) != 0) throw InputError(file + ": not a keyframe mesh sequence (bad magic)");
  uint32_t M = 0, F = 0;
  MeshSequence seq;
  get(M, "mesh count");
  get(F, "frame count");
  get(seq.fps, "fps");
  if (M == 0 || M > kMaxMeshes || F == 0 || F > kMaxFrames || !std::isfinite(seq.fps) || seq.fps <= 0)
    throw InputError(file + ": header out of range (meshes " + std::to_string(M) + ", frames " + std::to_string(F) +
                     ")");
  uint64_t total = 0;
  for (uint32_t m = 0; m < M; ++m) {
    SequenceMesh mesh;
    uint32_t len = 0, V = 0, T = 0;
    get(len, "mesh name");
    if (len == 0 || len > kMaxName) throw InputError(file + ": mesh " + std::to_string(m) + " name length out of range");
    mesh.name.resize(len);
    in.read(mesh.name.data(), len);
    get(V, "vertex count");
    get(T, "triangle count");
    if (V == 0 || V > kMaxVertices || T > 4 * uint64_t(kMaxVertices))
      throw InputError(file + ": mesh \"" + mesh.name + "\" size out of range (" + std::to_string(V) + " vertices, " +
                       std::to_string(T) + " triangles)");
    mesh.vertices = int(V);
    mesh.triangles.resize(3 * size_t(T));
    in.read(reinterpret_cast<char*>(mesh.triangles.data()), std::streamsize(12 * size_t(T)));
    if (!in) throw InputError(file + ": truncated (in the triangles of mesh \"" + mesh.name + "\")");
    for (uint32_t i : mesh.triangles)
      if (i >= V)
        throw InputError(file + ": mesh \"" + mesh.name + "\" has vertex index " + std::to_string(i) + " but " +
                         std::to_string(V) + " vertices");
    total += V;
    seq.meshes.push_back(std::move(mesh));
  }
  if (total > kMaxVertices) throw InputError(file + ": too many vertices (" + std::to_string(total) + ")");
  const auto header = uint64_t(in.tellg());
  const uint64_t expected = header + uint64_t(F) * total * 12;
  std::error_code ec;
  if (std::filesystem::file_size(path, ec) != expected)
    throw InputError(file + ": truncated or padded (expected " + std::to_string(expected) + " bytes for " +
                     std::to_string(F) + " frames of " + std::to_string(total) + " vertices)");
  seq.positions.assign(F, std::vector<float>(3 * size_t(total)));
  for (auto& f : seq.positions) in.read(reinterpret_cast<char*>(f.data()), std::streamsize(4 * f.size()));
  if (!in) throw InputError(file + ": truncated (in the frames)");
  for (const auto& f : seq.positions)
    for (float v : f)
      if (!std::isfinite(v)) throw InputError(file + ": non-finite vertex position");
  return seq;
}

}  // namespace kf
