#include "opt/evaluation_tape.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace kf
