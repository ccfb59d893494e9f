#include "opt/schedule_file.h"

#include <sys/stat.h>

#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/file_name.h"
#include "core/hash.h"
#include "core/warnings.h"
#include "sim/cloth/cloth_split_pattern.h"

namespace kf {
namespace fs = std::filesystem;

namespace {
constexpr char kMagic[8] = {'K', 'F', 'S', 'C', 'H', 'E', 'D', 'L'};
constexpr std::uint32_t kVersion = 1;
constexpr std::uint64_t kHeaderBytes = 8 + 4 + 4 + 4 + 8 + 8;

struct Header {
  std::uint32_t version = 0, substeps = 0, steps = 0;
  std::uint64_t fingerprint = 0, depths = 0;
};

template <class T>
void put(std::ostream& out, T value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof value);
}

template <class T>
bool get(std::istream& in, T& value) {
  return bool(in.read(reinterpret_cast<char*>(&value), sizeof value));
}

[[noreturn]] void refuse(const fs::path& path, const std::string& why) {
  throw InputError(printable(path.string()) + ": " + why);
}
}  // namespace

std::uint64_t controls_fingerprint(const VecX& z) { return fnv1a(z.data(), std::size_t(z.size()) * sizeof(double)); }

void save_schedule(const fs::path& path, const StepSchedule& schedule, const VecX& z, int substeps, int steps) {
  const ClothSystem::StepSchedule* held = cloth_split_steps(schedule);
  if (!held) {
    std::error_code ec;
    fs::remove(path, ec);
    return;
  }
  // Steps past a pattern's end decide afresh, as empty ones do: padded or cut, it steps the same.
  ClothSystem::StepSchedule cut(static_cast<std::size_t>(steps));
  for (std::size_t n = 0; n < cut.size() && n < held->size(); ++n) cut[n] = (*held)[n];
  std::uint64_t depths = 0;
  for (const auto& p : cut) depths += p.size();
  write_stream_atomic(path, [&](std::ostream& out) {
    out.write(kMagic, 8);
    put(out, kVersion);
    put(out, std::uint32_t(substeps));
    put(out, std::uint32_t(steps));
    put(out, controls_fingerprint(z));
    put(out, depths);
    for (const auto& p : cut) put(out, std::uint32_t(p.size()));
    for (const auto& p : cut) out.write(reinterpret_cast<const char*>(p.data()), std::streamsize(p.size()));
  });
}

StepSchedule load_schedule(const fs::path& path, const Scene& scene, const VecX& z, int substeps) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return {};
  // Opening a FIFO would wait for a writer, and a device would never end.
  if (!S_ISREG(st.st_mode)) refuse(path, "not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) refuse(path, "cannot be read");
  char magic[8];
  Header h;
  if (!in.read(magic, 8) || std::memcmp(magic, kMagic, 8) != 0)
    refuse(path, "not a keyframe step schedule (bad magic)");
  if (!get(in, h.version) || !get(in, h.substeps) || !get(in, h.steps) || !get(in, h.fingerprint) || !get(in, h.depths))
    refuse(path, "truncated step schedule (header)");
  if (h.version != kVersion)
    refuse(path, "step schedule version " + std::to_string(h.version) + ", expected " + std::to_string(kVersion));
  // Sizes are checked against the file before anything is allocated for them.
  const std::uint64_t size = std::uint64_t(st.st_size);
  if (h.depths > size || 4 * std::uint64_t(h.steps) > size ||
      kHeaderBytes + 4 * std::uint64_t(h.steps) + h.depths != size)
    refuse(path, "truncated or oversized step schedule (" + std::to_string(h.steps) + " steps and " +
                     std::to_string(h.depths) + " substeps claimed in " + std::to_string(size) + " bytes)");
  if (!scene.cloth) refuse(path, "a step schedule, but the scene has no cloth to hold it");
  TimeSpec time = scene.time;
  time.substeps = substeps;
  if (int(h.substeps) != substeps || std::int64_t(h.steps) != time.steps())
    refuse(path, "a step schedule of " + std::to_string(h.steps) + " steps at " + std::to_string(h.substeps) +
                     " substeps; the controls are for " + std::to_string(time.steps()) + " at " +
                     std::to_string(substeps));
  if (h.fingerprint != controls_fingerprint(z))
    refuse(path, "the step schedule of other controls than those beside it (remove it to choose the schedule anew)");
  std::vector<std::uint32_t> counts(h.steps);
  in.read(reinterpret_cast<char*>(counts.data()), std::streamsize(4 * counts.size()));
  std::uint64_t total = 0;
  for (std::uint32_t c : counts) total += c;
  if (!in || total != h.depths) refuse(path, "corrupt step schedule (its steps' substeps do not add up)");
  ClothSystem::StepSchedule steps(h.steps);
  for (std::size_t n = 0; n < steps.size(); ++n) {
    steps[n].resize(counts[n]);
    in.read(reinterpret_cast<char*>(steps[n].data()), std::streamsize(counts[n]));
    if (!in) refuse(path, "truncated step schedule");
    if (!is_split_pattern(steps[n], scene.cloth->max_halvings))
      refuse(path, "corrupt step schedule: step " + std::to_string(n) + "'s substeps do not tile it within " +
                       std::to_string(scene.cloth->max_halvings) + " halvings");
  }
  return cloth_split_schedule(std::move(steps));
}

StepSchedule run_schedule(const fs::path& dir, const Scene& scene, const VecX& z, int substeps) {
  const fs::path file = dir / "schedule.bin";
  StepSchedule s = load_schedule(file, scene, z, substeps);
  if (s.empty() && scene.cloth && scene.optimizer.split_schedule == SplitSchedule::kHeld)
    warn(printable(file.string()) +
         ": none stored (a run from before it was): the step schedule these controls "
         "are simulated under is chosen anew, and may not be the one the run's result was judged under");
  return s;
}

}  // namespace kf
