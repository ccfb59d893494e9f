#pragma once
// Every evaluation of an optimisation (its point z, objective, gradient and terms), kept so that an
// interrupted run resumes as if it had never stopped: the resumed optimisation starts again from the same
// initial guess and takes each recorded evaluation instead of recomputing it while its point matches bit
// for bit, so L-BFGS rebuilds the same memory, walks the same path and spends the same budget. A staged run
// records each stage's definition (its control count, kind, first frame and substeps): a resume runs the
// same stages again and a recorded evaluation is taken only in the stage it was made in, so a run resumes
// from any stage, and a finished run replays to its end without a new evaluation.
//
// File `evaluations.bin` (little endian): 8-byte magic "KFEVAL02"; uint64 stages, per stage uint64 controls,
// uint32 control kind (ControlKind), int32 first frame, uint32 substeps; uint64 count, then per evaluation:
// uint32 stage, float64 phi, float64 seconds, uint8 flags (1 diverged, 2 unstable, 4 the stop rule said the
// keyframes were reached), uint32 terms, per term (uint32 length, name bytes, float64 value), the stage's
// controls float64 z, as many float64 gradient; then uint64 FNV-1a hash of every byte before it.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/types.h"
#include "scene/objective_spec.h"

namespace kf {

// What defines a stage for the tape.
struct TapeStage {
  std::uint64_t controls = 0;
  ControlKind kind = ControlKind::kPerStep;
  int first_frame = 0;
  int substeps = 1;
  bool operator==(const TapeStage&) const = default;
  std::string describe() const;  // "27 controls (initial_lattice_velocity, from frame 0, 2 substeps)"
};

struct RecordedEvaluation {
  VecX z, g;
  double phi = 0, seconds = 0;
  bool diverged = false;
  bool unstable = false;  // diverged because the system refused a step as unstable
  bool reached = false;   // the stop rule said this point meets the keyframes (the run ended there)
  std::vector<std::pair<std::string, double>> terms;
  int stage = 0;          // index into the tape's stages
};

struct TapeContents {
  std::vector<TapeStage> stages;
  std::vector<RecordedEvaluation> records;
};

class EvaluationTape {
 public:
  // Recording stops (and the tape says so) past `max_bytes` of points and gradients.
  explicit EvaluationTape(std::uint64_t max_bytes = std::uint64_t(512) << 20) : max_bytes_(max_bytes) {}
  // A stage begins: later evaluations belong to it. Throws InputError naming `replay_file` when the replayed
  // tape recorded another definition for this stage.
  void begin_stage(const TapeStage& stage);
  // The recorded evaluation to use for the next point `z` of the current stage (bit-identical to the
  // recorded point), or nullptr once the replay has ended (a point or stage differs, or the records ran out).
  const RecordedEvaluation* replay(const VecX& z);
  void record(RecordedEvaluation e);
  // Records to replay (from `file`), before the optimisation starts.
  void set_replay(TapeContents contents, std::filesystem::path file) {
    replay_ = std::move(contents);
    replay_file_ = std::move(file);
  }
  bool complete() const { return complete_; }  // false when the size limit stopped the recording
  const TapeContents& contents() const { return recorded_; }
  const std::vector<RecordedEvaluation>& records() const { return recorded_.records; }
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

  TapeContents recorded_, replay_;
  std::filesystem::path replay_file_;
  int stage_ = -1;  // the current stage's index
  size_t next_ = 0;
  bool replaying_ = true, complete_ = true;
  std::uint64_t bytes_ = 0, max_bytes_;
};

// Writes atomically; throws OutputError.
void save_evaluations(const std::filesystem::path& path, const TapeContents& tape);
// Throws InputError naming the file when it is truncated, not an evaluations file, fails its checksum,
// holds a non-finite value, or an evaluation of a stage it does not define or with another control count.
TapeContents load_evaluations(const std::filesystem::path& path);

}  // namespace kf
