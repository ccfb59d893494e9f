#pragma once
// Every evaluation of an optimisation (its point z, objective, gradient and terms), kept so that an
// interrupted run resumes as if it had never stopped: the resumed optimisation starts again from the same
// initial guess and takes each recorded evaluation instead of recomputing it while its point matches bit
// for bit, so L-BFGS rebuilds the same memory, walks the same path and spends the same budget.
//
// File `evaluations.bin` (little endian): 8-byte magic "KFEVAL01", uint64 n (controls), uint64 count, then
// per evaluation: float64 phi, float64 seconds, uint8 diverged, uint32 terms, per term (uint32 length, name
// bytes, float64 value), n float64 z, n float64 gradient.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/types.h"

namespace kf {

struct RecordedEvaluation {
  VecX z, g;
  double phi = 0, seconds = 0;
  bool diverged = false;
  bool unstable = false;  // diverged because the system refused a step as unstable (stored as diverged = 2)
  std::vector<std::pair<std::string, double>> terms;
};

class EvaluationTape {
 public:
  // Recording stops (and the tape says so) past `max_bytes` of points and gradients.
  explicit EvaluationTape(std::uint64_t max_bytes = std::uint64_t(512) << 20) : max_bytes_(max_bytes) {}
  // The recorded evaluation to use for the next point `z` (bit-identical to the recorded point), or
  // nullptr once the replay has ended (a point differs or the records ran out).
  const RecordedEvaluation* replay(const VecX& z);
  void record(RecordedEvaluation e);
  // Records to replay (from a file), before the optimisation starts.
  void set_replay(std::vector<RecordedEvaluation> records) { replay_ = std::move(records); }
  bool complete() const { return complete_; }  // false when the size limit stopped the recording
  const std::vector<RecordedEvaluation>& records() const { return records_; }
  int replayed() const { return int(next_); }
  // Stops recording for good when `evaluations` evaluations of n controls could pass the size limit: such
  // a tape would be dropped part way, having held its memory for nothing.
  void expect(std::uint64_t n, std::uint64_t evaluations) {
    if ((16 * n + 64) * evaluations > max_bytes_) stop_recording();
  }
  // The most this tape holds while recording `evaluations` evaluations of n controls (bytes).
  std::uint64_t bytes_for(std::uint64_t n, std::uint64_t evaluations) const {
    return complete_ ? std::min(max_bytes_, (16 * n + 64) * evaluations) : 0;
  }

 private:
  void stop_recording();

  std::vector<RecordedEvaluation> records_, replay_;
  size_t next_ = 0;
  bool replaying_ = true, complete_ = true;
  std::uint64_t bytes_ = 0, max_bytes_;
};

// Writes atomically; throws OutputError.
void save_evaluations(const std::filesystem::path& path, const std::vector<RecordedEvaluation>& records);
// Throws InputError naming the file when it is truncated, not an evaluations file, or holds non-finite points.
std::vector<RecordedEvaluation> load_evaluations(const std::filesystem::path& path);

}  // namespace kf
