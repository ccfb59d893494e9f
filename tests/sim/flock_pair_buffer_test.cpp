// The flock's one pair buffer for forward and transposed terms: the larger kind sets its size, and each
// kind reads back what it wrote.
#include <gtest/gtest.h>

#include "sim/flock/neighbor_forces.h"
#include "sim/flock/pair_buffer.h"

namespace kf {
namespace {

TEST(PairBuffer, HoldsEitherKindInTheLargerKindsBytes) {
  PairBuffer buffer;
  EXPECT_EQ(buffer.as<PairForward>(0), nullptr);
  const std::size_t n = 1000;
  PairTransposed* t = buffer.as<PairTransposed>(n);
  EXPECT_EQ(buffer.bytes(), n * sizeof(PairTransposed));
  for (std::size_t k = 0; k < n; ++k) t[k] = {0, 0, 0, 0, 0, 0, 0, double(k)};
  EXPECT_EQ(t[n - 1].kcz, double(n - 1));
  PairForward* f = buffer.as<PairForward>(n);  // fits in the transposed terms' bytes: the same storage
  EXPECT_EQ(static_cast<void*>(f), static_cast<void*>(t));
  EXPECT_EQ(buffer.bytes(), n * sizeof(PairTransposed));
  for (std::size_t k = 0; k < n; ++k) f[k] = {double(k), 0, 0, 0, 0, 0, -double(k)};
  EXPECT_EQ(f[n - 1].ax, double(n - 1));
  EXPECT_EQ(f[n - 1].w, -double(n - 1));
  t = buffer.as<PairTransposed>(n);
  EXPECT_EQ(static_cast<void*>(t), static_cast<void*>(f));
  buffer.as<PairTransposed>(n + 1);  // grows by half at least
  EXPECT_GE(buffer.bytes(), n * sizeof(PairTransposed) * 3 / 2);
}

}  // namespace
}  // namespace kf
