#include "core/check.h"

#include <cfenv>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <functional>
#include <gtest/gtest.h>

namespace kf {
namespace {

TEST(Check, PassingChecksDoNothing) {
  CHECK(1 + 1 == 2);
  CHECK_EQ(3, 3);
  CHECK_NE(3, 4);
  CHECK_LT(1.0, 2.0);
  CHECK_LE(2, 2);
  CHECK_GT(2.5, 2.0);
  CHECK_GE(2, 2);
}

TEST(CheckDeathTest, FailurePrintsBothValuesAndExitsInternal) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const double residual = 0.25, tol = 1e-3;
  EXPECT_EXIT(CHECK_LT(residual, tol), testing::ExitedWithCode(10),
              "internal error: .*check_test.cpp:[0-9]+: CHECK_LT\\(residual, tol\\) failed: 0.25 vs 0.001");
  EXPECT_EXIT(CHECK(residual < 0), testing::ExitedWithCode(10), "CHECK\\(residual < 0\\) failed");
}

// The test main traps invalid operations and divisions by zero (tests/test_main.cpp; under ctest every
// test runs in its own process, and this one with traps).
TEST(FloatingPointTrapsDeathTest, InvalidOperationAndDivisionByZeroTrap) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  if (!(fegetexcept() & FE_INVALID))
    GTEST_SKIP() << "traps are off in this process (KEYFRAME_NO_FP_TRAPS=1, or an untrapped test runs beside this one)";
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer catches SIGFPE itself, reports it and exits with status 1.
  const std::function<bool(int)> trapped = testing::ExitedWithCode(1);
  const char* const report = "AddressSanitizer: FPE";
#else
  const std::function<bool(int)> trapped = testing::KilledBySignal(SIGFPE);
  const char* const report = "";
#endif
  volatile double zero = 0.0, minus_one = -1.0;
  EXPECT_EXIT(std::printf("%g\n", 1.0 / zero), trapped, report);
  EXPECT_EXIT(std::printf("%g\n", std::sqrt(minus_one)), trapped, report);
}

}  // namespace
}  // namespace kf
