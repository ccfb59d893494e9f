// The PCG warm start: exact on solutions that change quadratically from step to step, in either direction;
// no guess for a step that does not follow the last one; a saved history restores the same guess.
#include <gtest/gtest.h>

#include "sim/cloth/warm_start.h"

namespace kf {
namespace {

VecX quadratic(int n) { return VecX::LinSpaced(6, 1, 6) + 0.5 * n * VecX::Ones(6) - 0.25 * n * n * VecX::Ones(6); }

TEST(WarmStart, ExtrapolatesAQuadraticSequenceExactlyInEitherDirection) {
  for (int dir : {+1, -1}) {
    WarmStart ws(dir);
    ws.resize(6);
    VecX x = VecX::Constant(6, 7.0);
    EXPECT_FALSE(ws.guess(10, x));
    EXPECT_EQ(x, VecX::Constant(6, 7.0));  // untouched without a history
    ws.remember(10, quadratic(10));
    ASSERT_TRUE(ws.guess(10 + dir, x));
    EXPECT_EQ(x, quadratic(10));  // one solution: itself
    ws.remember(10 + dir, quadratic(10 + dir));
    ws.remember(10 + 2 * dir, quadratic(10 + 2 * dir));
    ASSERT_TRUE(ws.guess(10 + 3 * dir, x));
    EXPECT_LT((x - quadratic(10 + 3 * dir)).norm(), 1e-12);
    EXPECT_FALSE(ws.guess(10 + 4 * dir, x));  // not the next step
  }
}

TEST(WarmStart, RestartsOnAGapAndCarriesItsHistoryThroughSaveAndRestore) {
  WarmStart ws(+1);
  ws.resize(6);
  for (int n = 0; n < 3; ++n) ws.remember(n, quadratic(n));
  ws.remember(7, quadratic(7));  // a gap: only step 7 is left
  VecX x;
  ASSERT_TRUE(ws.guess(8, x));
  EXPECT_EQ(x, quadratic(7));

  for (int n = 8; n < 10; ++n) ws.remember(n, quadratic(n));
  VecX context, saved_guess, restored_guess;
  ws.save(10, context);
  EXPECT_EQ(context.size(), 3 * 6);
  ASSERT_TRUE(ws.guess(10, saved_guess));
  WarmStart other(+1);
  other.resize(6);
  other.restore(10, context);
  ASSERT_TRUE(other.guess(10, restored_guess));
  EXPECT_TRUE(saved_guess == restored_guess);
  ws.save(12, context);  // nothing that step 12 could use
  EXPECT_EQ(context.size(), 0);
  other.restore(12, context);
  EXPECT_FALSE(other.guess(12, x));
}

}  // namespace
}  // namespace kf
