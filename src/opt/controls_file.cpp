#include "opt/controls_file.h"

#include <cstdint>
#include <cstring>
#include <fstream>

#include "core/atomic_file.h"
#include "core/error.h"

namespace kf {
namespace {
constexpr char kMagic[8] = {'K', 'F', 'C', 'T', 'R', 'L', '0', '1'};
}

void save_controls(const std::filesystem::path& path, const VecX& z, int substeps) {
  write_stream_atomic(path, [&](std::ostream& out) {
    const uint64_t n = uint64_t(z.size());
    const uint32_t s = uint32_t(substeps);
    out.write(kMagic, 8);
    out.write(reinterpret_cast<const char*>(&n), 8);
    out.write(reinterpret_cast<const char*>(&s), 4);
    out.write(reinterpret_cast<const char*>(z.data()), std::streamsize(8 * n));
  });
}

VecX load_controls(const std::filesystem::path& path, int* substeps) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": no saved controls to resume from");
  char magic[8];
  uint64_t n = 0;
  uint32_t s = 0;
  in.read(magic, 8);
  in.read(reinterpret_cast<char*>(&n), 8);
  in.read(reinterpret_cast<char*>(&s), 4);
  if (!in || std::memcmp(magic, kMagic, 8) != 0 || n > (uint64_t(1) << 34))
    throw InputError(path.string() + ": not a keyframe controls file (bad header)");
  std::error_code ec;
  if (std::filesystem::file_size(path, ec) != 20 + 8 * n) throw InputError(path.string() + ": truncated controls file");
  VecX z(static_cast<Eigen::Index>(n));
  in.read(reinterpret_cast<char*>(z.data()), std::streamsize(8 * n));
  if (!in || !z.allFinite()) throw InputError(path.string() + ": truncated or non-finite controls");
  if (substeps) *substeps = int(s);
  return z;
}

}  // namespace kf
