#include "opt/evaluation_tape.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <ostream>

#include "core/atomic_file.h"
#include "core/error.h"

namespace kf {
namespace {
constexpr char kMagic[8] = {'K', 'F', 'E', 'V', 'A', 'L', '0', '1'};

template <typename T>
void put(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof v);
}

// Reads from a byte buffer; every read is checked against its end.
struct Reader {
  const std::string& bytes;
  size_t at = 0;
  bool take(void* dst, size_t n) {
    if (n > bytes.size() - at) return false;
    std::memcpy(dst, bytes.data() + at, n);
    at += n;
    return true;
  }
};
}  // namespace

const RecordedEvaluation* EvaluationTape::replay(const VecX& z) {
  if (!replaying_ || next_ >= replay_.size()) {
    replaying_ = false;
    return nullptr;
  }
  const RecordedEvaluation& r = replay_[next_];
  if (r.z.size() != z.size() || std::memcmp(r.z.data(), z.data(), sizeof(double) * size_t(z.size())) != 0) {
    replaying_ = false;
    return nullptr;
  }
  ++next_;
  return &r;
}

void EvaluationTape::record(RecordedEvaluation e) {
  if (!complete_) return;
  bytes_ += 16 * std::uint64_t(e.z.size()) + 64;
  if (bytes_ > max_bytes_) return stop_recording();
  records_.push_back(std::move(e));
}

void EvaluationTape::stop_recording() {
  complete_ = false;
  records_.clear();
  records_.shrink_to_fit();
}

void save_evaluations(const std::filesystem::path& path, const std::vector<RecordedEvaluation>& records) {
  write_stream_atomic(path, [&](std::ostream& out) {
    out.write(kMagic, 8);
    put(out, std::uint64_t(records.empty() ? 0 : records.front().z.size()));
    put(out, std::uint64_t(records.size()));
    for (const auto& r : records) {
      put(out, r.phi);
      put(out, r.seconds);
      put(out, std::uint8_t(r.unstable ? 2 : r.diverged ? 1 : 0));
      put(out, std::uint32_t(r.terms.size()));
      for (const auto& [name, value] : r.terms) {
        put(out, std::uint32_t(name.size()));
        out.write(name.data(), std::streamsize(name.size()));
        put(out, value);
      }
      out.write(reinterpret_cast<const char*>(r.z.data()), std::streamsize(8 * r.z.size()));
      out.write(reinterpret_cast<const char*>(r.g.data()), std::streamsize(8 * r.g.size()));
    }
  });
}

std::vector<RecordedEvaluation> load_evaluations(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot read the recorded evaluations");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Reader r{bytes};
  char magic[8];
  std::uint64_t n = 0, count = 0;
  const auto bad = [&](const std::string& why) { return InputError(path.string() + ": " + why); };
  if (!r.take(magic, 8) || std::memcmp(magic, kMagic, 8) != 0 || !r.take(&n, 8) || !r.take(&count, 8))
    throw bad("not a keyframe evaluations file (bad header)");
  // Each record holds at least its fixed fields and 2n doubles: a count the file cannot hold is refused
  // before anything is allocated for it.
  const std::uint64_t min_record = 21 + 16 * n;
  if (n > (std::uint64_t(1) << 31) || count > (bytes.size() - r.at) / min_record)
    throw bad("truncated (the header promises " + std::to_string(count) + " evaluations of " + std::to_string(n) +
              " controls)");
  std::vector<RecordedEvaluation> out(count);
  for (std::uint64_t k = 0; k < count; ++k) {
    RecordedEvaluation& e = out[k];
    std::uint8_t diverged = 0;
    std::uint32_t terms = 0;
    if (!r.take(&e.phi, 8) || !r.take(&e.seconds, 8) || !r.take(&diverged, 1) || !r.take(&terms, 4))
      throw bad("truncated at evaluation " + std::to_string(k + 1));
    e.diverged = diverged != 0;
    e.unstable = diverged == 2;
    if (terms > 10000) throw bad("evaluation " + std::to_string(k + 1) + " claims " + std::to_string(terms) + " terms");
    for (std::uint32_t t = 0; t < terms; ++t) {
      std::uint32_t len = 0;
      double value = 0;
      if (!r.take(&len, 4) || len > 1024 || len > bytes.size() - r.at) throw bad("truncated at evaluation " + std::to_string(k + 1));
      std::string name(bytes.data() + r.at, len);
      r.at += len;
      if (!r.take(&value, 8)) throw bad("truncated at evaluation " + std::to_string(k + 1));
      e.terms.emplace_back(std::move(name), value);
    }
    e.z.resize(Eigen::Index(n));
    e.g.resize(Eigen::Index(n));
    if (!r.take(e.z.data(), 8 * n) || !r.take(e.g.data(), 8 * n))
      throw bad("truncated at evaluation " + std::to_string(k + 1));
    if (!e.z.allFinite() || !std::isfinite(e.seconds))
      throw bad("evaluation " + std::to_string(k + 1) + " holds a non-finite point");
  }
  if (r.at != bytes.size()) throw bad("has " + std::to_string(bytes.size() - r.at) + " bytes after the last evaluation");
  return out;
}

}  // namespace kf
