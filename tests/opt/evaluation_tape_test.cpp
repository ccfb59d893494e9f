#include "opt/evaluation_tape.h"

#include <gtest/gtest.h>

#include <filesystem>

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
  save_evaluations(path, records);
  const auto back = load_evaluations(path);
  std::filesystem::remove(path);
  ASSERT_EQ(back.size(), 3u);
  EXPECT_FALSE(back[0].diverged || back[0].unstable);
  EXPECT_TRUE(back[1].diverged && !back[1].unstable);
  EXPECT_TRUE(back[2].diverged && back[2].unstable);
}

}  // namespace
}  // namespace kf
