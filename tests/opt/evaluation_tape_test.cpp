#include "opt/evaluation_tape.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "core/error.h"

namespace kf {
namespace {

RecordedEvaluation evaluation_of(int n, double value) {
  RecordedEvaluation e;
  e.z = VecX::Constant(n, value);
  e.g = VecX::Constant(n, -value);
  e.phi = value;
  return e;
}

// A run whose evaluations cannot all fit the tape records none: before, it held the tape's whole limit
// until the limit was passed and then dropped it, so the memory was spent and the resume lost anyway.
TEST(EvaluationTape, ARunThatCannotFitIsNotRecordedAtAll) {
  const int n = 1000;
  const std::uint64_t per_evaluation = 16 * n + 64;
  EvaluationTape tape(10 * per_evaluation);
  EXPECT_EQ(tape.bytes_for(n, 60), 10 * per_evaluation);
  tape.expect(n, 60);
  EXPECT_FALSE(tape.complete());
  EXPECT_EQ(tape.bytes_for(n, 60), 0u);
  tape.record(evaluation_of(n, 1.0));
  EXPECT_TRUE(tape.records().empty());
}

TEST(EvaluationTape, ARunThatFitsIsRecordedWhole) {
  const int n = 1000;
  const std::uint64_t per_evaluation = 16 * n + 64;
  EvaluationTape tape(10 * per_evaluation);
  tape.expect(n, 10);
  EXPECT_TRUE(tape.complete());
  EXPECT_EQ(tape.bytes_for(n, 10), 10 * per_evaluation);
  for (int k = 0; k < 10; ++k) tape.record(evaluation_of(n, k));
  ASSERT_EQ(tape.records().size(), 10u);
  EXPECT_EQ(tape.records().back().phi, 9.0);
  // One more than it expected passes the limit: the tape says it is incomplete and holds nothing.
  tape.record(evaluation_of(n, 10));
  EXPECT_FALSE(tape.complete());
  EXPECT_TRUE(tape.records().empty());
}

// A diverged evaluation keeps whether the system refused it as unstable, so a resumed run's optimiser
// refuses the same later trials unsimulated as the first run did.
TEST(EvaluationTape, UnstableEvaluationsRoundTrip) {
  std::vector<RecordedEvaluation> records = {evaluation_of(3, 1.0), evaluation_of(3, 2.0), evaluation_of(3, 3.0)};
  records[1].diverged = true;
  records[2].diverged = records[2].unstable = true;
  const auto path = std::filesystem::temp_directory_path() / "kf_tape_unstable.bin";
  save_evaluations(path, {{{3, ControlKind::kPerFrame, 0, 1}}, records});
  const auto back = load_evaluations(path).records;
  std::filesystem::remove(path);
  ASSERT_EQ(back.size(), 3u);
  EXPECT_FALSE(back[0].diverged || back[0].unstable);
  EXPECT_TRUE(back[1].diverged && !back[1].unstable);
  EXPECT_TRUE(back[2].diverged && back[2].unstable);
}

// A staged run's tape: each stage's definition and its evaluations, each of its stage's size.
TapeContents staged_tape() {
  TapeContents t;
  t.stages = {{6, ControlKind::kInitialRigidVelocity, 0, 1}, {27, ControlKind::kInitialLatticeVelocity, 0, 1},
              {75, ControlKind::kInitialVelocity, 0, 1}};
  for (int s = 0; s < 3; ++s)
    for (int k = 0; k < 2; ++k) {
      RecordedEvaluation e = evaluation_of(int(t.stages[s].controls), s + 0.5 * k);
      e.stage = s;
      e.terms = {{"center_of_mass@20", 0.25 * k}, {"effort", 1e-3}};
      e.reached = s == 2 && k == 1;
      t.records.push_back(e);
    }
  return t;
}

std::filesystem::path tape_file(const char* name) { return std::filesystem::temp_directory_path() / name; }

TEST(EvaluationTape, StagesOfDifferentSizesRoundTrip) {
  const TapeContents t = staged_tape();
  const auto path = tape_file("kf_tape_staged.bin");
  save_evaluations(path, t);
  const TapeContents back = load_evaluations(path);
  std::filesystem::remove(path);
  ASSERT_EQ(back.stages.size(), 3u);
  EXPECT_TRUE(back.stages == t.stages);
  ASSERT_EQ(back.records.size(), t.records.size());
  for (size_t k = 0; k < t.records.size(); ++k) {
    EXPECT_EQ(back.records[k].stage, t.records[k].stage);
    EXPECT_EQ(back.records[k].z, t.records[k].z);
    EXPECT_EQ(back.records[k].g, t.records[k].g);
    EXPECT_EQ(back.records[k].terms, t.records[k].terms);
    EXPECT_EQ(back.records[k].reached, t.records[k].reached);
  }
}

// The replay gives a stage only its own evaluations, and refuses a stage the file defined otherwise.
TEST(EvaluationTape, ReplayFollowsTheStages) {
  const TapeContents t = staged_tape();
  EvaluationTape tape;
  tape.set_replay(t, "run/evaluations.bin");
  tape.begin_stage(t.stages[0]);
  EXPECT_NE(tape.replay(t.records[0].z), nullptr);
  EXPECT_NE(tape.replay(t.records[1].z), nullptr);
  EXPECT_EQ(tape.replay(t.records[1].z), nullptr);  // stage 1 has no third evaluation: the replay ends
  EvaluationTape other;
  other.set_replay(t, "run/evaluations.bin");
  other.begin_stage(t.stages[0]);
  TapeStage wrong = t.stages[1];
  wrong.controls = 28;
  try {
    other.begin_stage(wrong);
    FAIL() << "a stage of another size was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("run/evaluations.bin: stage 2 was recorded with 27 controls", 0), 0u) << e.what();
  }
}

// Any changed byte, a non-finite value or a record of a stage the file does not define is refused, naming
// the file.
TEST(EvaluationTape, DamagedFilesAreRefusedNamingTheFile) {
  const auto path = tape_file("kf_tape_damaged.bin");
  save_evaluations(path, staged_tape());
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const auto refused = [&](std::string b, const std::string& why) {
    std::ofstream(path, std::ios::binary) << b;
    try {
      (void)load_evaluations(path);
      ADD_FAILURE() << why << ": accepted";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(path.string() + ": ", 0), 0u) << m;
      EXPECT_NE(m.find(why), std::string::npos) << m;
    }
  };
  // The first evaluation's phi, one bit changed: only the checksum sees it.
  const size_t stage_table = 8 + 8 + 3 * 20 + 8;
  std::string flipped = bytes;
  flipped[stage_table + 4 + 3] ^= 1;
  refused(flipped, "checksum mismatch");
  // A NaN phi with the checksum made to match is still refused.
  std::string nan = bytes.substr(0, bytes.size() - 8);
  const double q = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(nan.data() + stage_table + 4, &q, 8);
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (char c : nan) h = (h ^ std::uint8_t(c)) * 0x100000001b3ULL;
  nan.append(reinterpret_cast<const char*>(&h), 8);
  refused(nan, "non-finite");
  refused(bytes.substr(0, bytes.size() - 5), "truncated");
  refused("KFEVAL01" + bytes.substr(8), "bad header");
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace kf
