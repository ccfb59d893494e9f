#include "core/trajectory.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <ostream>

#include "core/atomic_file.h"
#include "core/error.h"

namespace kf {
namespace {
constexpr char kMagic[8] = {'K', 'F', 'T', 'R', 'A', 'J', '0', '1'};
}

void save_trajectory(const std::filesystem::path& path, const Trajectory& t) {
  write_stream_atomic(path, [&](std::ostream& out) {
    out.write(kMagic, 8);
    uint32_t p = uint32_t(t.particles), f = uint32_t(t.frames());
    out.write(reinterpret_cast<const char*>(&p), 4);
    out.write(reinterpret_cast<const char*>(&f), 4);
    out.write(reinterpret_cast<const char*>(&t.fps), 8);
    for (int k = 0; k < t.frames(); ++k) {
      out.write(reinterpret_cast<const char*>(t.x[k].data()), std::streamsize(8 * 3 * p));
      out.write(reinterpret_cast<const char*>(t.v[k].data()), std::streamsize(8 * 3 * p));
    }
  });
}

Trajectory load_trajectory(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": no trajectory here (run `keyframe simulate` or `optimize` first)");
  char magic[8];
  uint32_t p = 0, f = 0;
  Trajectory t;
  in.read(magic, 8);
  in.read(reinterpret_cast<char*>(&p), 4);
  in.read(reinterpret_cast<char*>(&f), 4);
  in.read(reinterpret_cast<char*>(&t.fps), 8);
  if (!in || std::memcmp(magic, kMagic, 8) != 0)
    throw InputError(path.string() + ": not a keyframe trajectory (bad header)");
  if (p == 0 || p > 10'000'000 || f == 0 || f > 1'000'000 || !std::isfinite(t.fps) || t.fps <= 0)
    throw InputError(path.string() + ": header out of range (particles " + std::to_string(p) + ", frames " +
                     std::to_string(f) + ")");
  const auto expected = std::uintmax_t(24) + std::uintmax_t(f) * p * 6 * 8;
  std::error_code ec;
  if (std::filesystem::file_size(path, ec) != expected)
    throw InputError(path.string() + ": truncated or padded (expected " + std::to_string(expected) + " bytes)");
  t.particles = int(p);
  t.x.resize(f);
  t.v.resize(f);
  for (uint32_t k = 0; k < f; ++k) {
    t.x[k].resize(3 * p);
    t.v[k].resize(3 * p);
    in.read(reinterpret_cast<char*>(t.x[k].data()), std::streamsize(8 * 3 * p));
    in.read(reinterpret_cast<char*>(t.v[k].data()), std::streamsize(8 * 3 * p));
  }
  if (!in) throw InputError(path.string() + ": truncated");
  for (uint32_t k = 0; k < f; ++k)
    if (!t.x[k].allFinite() || !t.v[k].allFinite())
      throw InputError(path.string() + ": frame " + std::to_string(k) + " holds a non-finite " +
                       (t.x[k].allFinite() ? "velocity" : "position") + " (NaN or infinity)");
  return t;
}

}  // namespace kf
