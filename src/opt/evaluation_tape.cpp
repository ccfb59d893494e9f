#include "opt/evaluation_tape.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hash.h"

namespace kf {
namespace {
constexpr char kMagic[8] = {'K', 'F', 'E', 'V', 'A', 'L', '0', '2'};
constexpr std::uint8_t kDiverged = 1, kUnstable = 2, kReached = 4;
constexpr int kControlKinds = int(ControlKind::kPerFrameLattice) + 1;

template <typename T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

// Reads from a byte buffer; every read is checked against its end.
struct Reader {
  const std::string& bytes;
  size_t end;  // the checksum's start
  size_t at = 0;
  bool take(void* dst, size_t n) {
    if (n > end - at) return false;
    std::memcpy(dst, bytes.data() + at, n);
    at += n;
    return true;
  }
};

std::string contents_bytes(const TapeContents& tape) {
  std::string out(kMagic, 8);
  put(out, std::uint64_t(tape.stages.size()));
  for (const TapeStage& s : tape.stages) {
    put(out, s.controls);
    put(out, std::uint32_t(s.kind));
    put(out, std::int32_t(s.first_frame));
    put(out, std::uint32_t(s.substeps));
  }
  put(out, std::uint64_t(tape.records.size()));
  for (const auto& r : tape.records) {
    put(out, std::uint32_t(r.stage));
    put(out, r.phi);
    put(out, r.seconds);
    put(out, std::uint8_t((r.diverged ? kDiverged : 0) | (r.unstable ? kUnstable : 0) | (r.reached ? kReached : 0)));
    put(out, std::uint32_t(r.terms.size()));
    for (const auto& [name, value] : r.terms) {
      put(out, std::uint32_t(name.size()));
      out.append(name);
      put(out, value);
    }
    out.append(reinterpret_cast<const char*>(r.z.data()), 8 * size_t(r.z.size()));
    out.append(reinterpret_cast<const char*>(r.g.data()), 8 * size_t(r.g.size()));
  }
  return out;
}

}  // namespace

std::string TapeStage::describe() const {
  std::ostringstream os;
  os << controls << " controls (" << control_kind_name(kind) << ", from frame " << first_frame << ", " << substeps
     << " substeps)";
  return os.str();
}

void EvaluationTape::begin_stage(const TapeStage& stage) {
  ++stage_;
  if (size_t(stage_) < replay_.stages.size() && !(replay_.stages[stage_] == stage))
    throw InputError(replay_file_.string() + ": stage " + std::to_string(stage_ + 1) + " was recorded with " +
                     replay_.stages[stage_].describe() + ", the run's plan gives it " + stage.describe() +
                     ": not this scene's run (remove evaluations.bin to continue from controls.bin)");
  if (complete_) recorded_.stages.push_back(stage);
}

const RecordedEvaluation* EvaluationTape::replay(const VecX& z) {
  if (!replaying_ || next_ >= replay_.records.size() || replay_.records[next_].stage != std::max(0, stage_)) {
    replaying_ = false;
    return nullptr;
  }
  const RecordedEvaluation& r = replay_.records[next_];
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
  e.stage = std::max(0, stage_);
  if (recorded_.stages.empty()) recorded_.stages.push_back({std::uint64_t(e.z.size())});
  recorded_.records.push_back(std::move(e));
}

void EvaluationTape::stop_recording() {
  complete_ = false;
  recorded_ = TapeContents();
  recorded_.records.shrink_to_fit();
}

void save_evaluations(const std::filesystem::path& path, const TapeContents& tape) {
  std::string bytes = contents_bytes(tape);
  put(bytes, fnv1a(bytes.data(), bytes.size()));
  write_file_atomic(path, bytes);
}

namespace {

std::vector<TapeStage> read_stages(Reader& r, const std::function<InputError(const std::string&)>& bad) {
  std::uint64_t count = 0;
  if (!r.take(&count, 8)) throw bad("truncated (no stage table)");
  if (count > (r.end - r.at) / 20) throw bad("truncated (the header promises " + std::to_string(count) + " stages)");
  std::vector<TapeStage> stages(count);
  for (std::uint64_t k = 0; k < count; ++k) {
    std::uint32_t kind = 0, substeps = 0;
    std::int32_t first = 0;
    TapeStage& s = stages[k];
    if (!r.take(&s.controls, 8) || !r.take(&kind, 4) || !r.take(&first, 4) || !r.take(&substeps, 4))
      throw bad("truncated in the stage table");
    if (s.controls > (std::uint64_t(1) << 31) || kind >= std::uint32_t(kControlKinds) || first < 0 || substeps < 1)
      throw bad("stage " + std::to_string(k + 1) + " has an impossible definition");
    s.kind = ControlKind(kind);
    s.first_frame = first;
    s.substeps = int(substeps);
  }
  return stages;
}

void read_record(Reader& r, const std::vector<TapeStage>& stages, std::uint64_t k, RecordedEvaluation& e,
                 const std::function<InputError(const std::string&)>& bad) {
  const std::string which = "evaluation " + std::to_string(k + 1);
  std::uint32_t stage = 0, terms = 0;
  std::uint8_t flags = 0;
  if (!r.take(&stage, 4) || !r.take(&e.phi, 8) || !r.take(&e.seconds, 8) || !r.take(&flags, 1) || !r.take(&terms, 4))
    throw bad("truncated at " + which);
  if (stage >= stages.size()) throw bad(which + " belongs to stage " + std::to_string(stage + 1) + ", which it does not define");
  e.stage = int(stage);
  e.diverged = flags & kDiverged;
  e.unstable = flags & kUnstable;
  e.reached = flags & kReached;
  if (terms > 10000) throw bad(which + " claims " + std::to_string(terms) + " terms");
  for (std::uint32_t t = 0; t < terms; ++t) {
    std::uint32_t len = 0;
    double value = 0;
    if (!r.take(&len, 4) || len > 1024 || len > r.end - r.at) throw bad("truncated at " + which);
    std::string name(r.bytes.data() + r.at, len);
    r.at += len;
    if (!r.take(&value, 8)) throw bad("truncated at " + which);
    if (!std::isfinite(value)) throw bad(which + " holds a non-finite term");
    e.terms.emplace_back(std::move(name), value);
  }
  const std::uint64_t n = stages[stage].controls;
  if (2 * 8 * n > r.end - r.at) throw bad("truncated at " + which);
  e.z.resize(Eigen::Index(n));
  e.g.resize(Eigen::Index(n));
  if (!r.take(e.z.data(), 8 * n) || !r.take(e.g.data(), 8 * n)) throw bad("truncated at " + which);
  if (!e.z.allFinite() || !e.g.allFinite() || !std::isfinite(e.phi) || !std::isfinite(e.seconds))
    throw bad(which + " holds a non-finite value");
}

}  // namespace

TapeContents load_evaluations(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot read the recorded evaluations");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::function<InputError(const std::string&)> bad = [&](const std::string& why) {
    return InputError(path.string() + ": " + why);
  };
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kMagic, 8) != 0)
    throw bad("not a keyframe evaluations file (bad header)");
  if (bytes.size() < 8 + 8 + 8 + 8) throw bad("truncated (no checksum)");
  Reader r{bytes, bytes.size() - 8, 8};
  TapeContents tape;
  tape.stages = read_stages(r, bad);
  std::uint64_t count = 0;
  if (!r.take(&count, 8)) throw bad("truncated (no evaluation count)");
  // Each record holds at least its fixed fields: a count the file cannot hold is refused before anything is
  // allocated for it.
  if (count > (r.end - r.at) / 25) throw bad("truncated (the header promises " + std::to_string(count) + " evaluations)");
  tape.records.resize(count);
  for (std::uint64_t k = 0; k < count; ++k) read_record(r, tape.stages, k, tape.records[k], bad);
  if (r.at != r.end) throw bad("has " + std::to_string(r.end - r.at) + " bytes after the last evaluation");
  std::uint64_t sum = 0;
  std::memcpy(&sum, bytes.data() + r.end, 8);
  if (sum != fnv1a(bytes.data(), r.end)) throw bad("checksum mismatch: the file was changed or damaged after it was written");
  return tape;
}

}  // namespace kf
