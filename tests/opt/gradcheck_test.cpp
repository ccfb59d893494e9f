// The finite differences a gradient check trusts: extrapolated central differences that converge on
// strongly curved functions, see through round-off, and refuse to call a kink a derivative.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>

#include "opt/gradcheck.h"

namespace kf {
namespace {

// Deterministic round-off-like noise of amplitude a at x (a hash of x's bits).
double noise(double x, double a) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  b ^= b >> 33;
  b *= 0xff51afd7ed558ccdULL;
  b ^= b >> 33;
  return a * (double(b >> 11) / double(1ULL << 53) - 0.5);
}

DifferenceEstimate differentiate(const std::function<double(double)>& f, double x, double step, double sigma) {
  return extrapolated_difference(step, [&](double h) { return (f(x + h) - f(x - h)) / (2 * h); }, 1e-9, sigma);
}

TEST(ExtrapolatedDifference, SmoothFunctionToRoundOff) {
  const DifferenceEstimate e = differentiate([](double x) { return std::sin(3 * x) * std::exp(x); }, 0.4, 1e-2, 0);
  const double exact = (3 * std::cos(1.2) + std::sin(1.2)) * std::exp(0.4);
  EXPECT_NEAR(e.value, exact, 1e-9 * std::abs(exact));
  EXPECT_LT(e.error, 1e-8 * std::abs(exact));
}

// Curvature on a scale a hundred times below the first step (as a stiff contact near its onset gives):
// the first differences are far off, the steps shrink until they converge.
TEST(ExtrapolatedDifference, ConvergesWhereTheFirstStepsAreFarOff) {
  const double s = 1e-6;
  const auto f = [s](double x) {  // s log cosh(x/s) + 2x, f' = tanh(x/s) + 2, without overflow
    const double y = std::abs(x / s);
    return s * (y + std::log1p(std::exp(-2 * y)) - std::log(2.0)) + 2 * x;
  };
  const double x = 0.3 * s, exact = std::tanh(0.3) + 2;
  EXPECT_GT(std::abs((f(x + 1e-4) - f(x - 1e-4)) / 2e-4 - exact), 0.1);
  const DifferenceEstimate e = differentiate(f, x, 1e-4, 0);
  EXPECT_NEAR(e.value, exact, 1e-7);
  EXPECT_LT(e.error, 1e-6);
}

// With round-off of amplitude 1e-13 in f the estimate stays at steps where it does not dominate, and the
// error estimate covers the error actually made.
TEST(ExtrapolatedDifference, ErrorEstimateCoversRoundOff) {
  for (double amplitude : {1e-14, 1e-13, 1e-12}) {
    const double sigma = amplitude / std::sqrt(12.0);  // uniform noise of width `amplitude`
    const auto f = [amplitude](double x) { return 150 + 2e-3 * x + 0.5 * x * x + noise(x, amplitude); };
    const DifferenceEstimate e = differentiate(f, 0.1, 1e-4, sigma);
    const double exact = 2e-3 + 0.1;
    EXPECT_LE(std::abs(e.value - exact), e.error) << amplitude;
    EXPECT_LT(e.error, 1e3 * amplitude / 1e-4) << amplitude;
  }
}

// A kink 1e-6 away: the steps shrink past it and the estimate is the slope on the point's own side.
TEST(ExtrapolatedDifference, StepsShrinkPastANearbyKink) {
  const auto f = [](double x) { return x < 1e-6 ? x : 3 * x - 2e-6; };
  const DifferenceEstimate e = differentiate(f, 0.0, 1e-4, 0);
  EXPECT_NEAR(e.value, 1.0, 1e-9);
}

// A jump of f at the point (a contact that starts, a step split differently): the differences grow without
// bound as the steps shrink, and the error estimate covers what the jump adds to the estimate.
TEST(ExtrapolatedDifference, JumpIsCoveredByTheErrorEstimate) {
  for (double jump : {1e-9, 1e-6, 1e-3}) {
    const auto f = [jump](double x) { return x + (x > 0 ? jump : 0.0); };
    const DifferenceEstimate e = differentiate(f, 0.0, 1e-4, 0);
    EXPECT_LE(std::abs(e.value - 1.0), e.error) << jump;
  }
}

}  // namespace
}  // namespace kf
