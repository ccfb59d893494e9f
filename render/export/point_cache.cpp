#include "render/export/point_cache.h"

#include <cstdint>
#include <cstring>
#include <ostream>

#include "core/atomic_file.h"

namespace kf::render {

void write_rest_obj(const std::filesystem::path& path, const MovingMesh& mesh) {
  write_stream_atomic(path, [&](std::ostream& out) {
    out << "# keyframe: rest shape of \"" << mesh.name << "\" (metres, Y up)"
        << (mesh.vertices.empty() ? "" : "; " + mesh.vertices) << "\n";
    out << "o " << mesh.name << "\n";
    const auto& p = mesh.positions.front();
    for (size_t i = 0; i + 2 < p.size(); i += 3) out << "v " << p[i] << " " << p[i + 1] << " " << p[i + 2] << "\n";
    for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
      out << "f " << mesh.indices[t] + 1 << " " << mesh.indices[t + 1] + 1 << " " << mesh.indices[t + 2] + 1 << "\n";
  });
}

void write_pc2(const std::filesystem::path& path, const MovingMesh& mesh, int start_frame) {
  static_assert(sizeof(float) == 4 && sizeof(int32_t) == 4);
  write_stream_atomic(path, [&](std::ostream& out) {
    auto put = [&](const void* data, size_t bytes) { out.write(static_cast<const char*>(data), std::streamsize(bytes)); };
    const char signature[12] = "POINTCACHE2";  // and its terminating zero
    const int32_t version = 1, points = int32_t(mesh.positions.front().size() / 3),
                  samples = int32_t(mesh.positions.size());
    const float start = float(start_frame), rate = 1.0f;
    put(signature, 12);
    put(&version, 4);
    put(&points, 4);
    put(&start, 4);
    put(&rate, 4);
    put(&samples, 4);
    for (const auto& frame : mesh.positions) put(frame.data(), frame.size() * sizeof(float));
  });
}

}  // namespace kf::render
