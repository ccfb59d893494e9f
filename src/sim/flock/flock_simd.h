#pragma once
// Whether the flock's neighbour passes (the neighbour scan and the pair terms) may work on eight neighbours
// at once with AVX-512. They give the scalar code's results bit for bit: the same operations in the same
// order, no fused multiply-add, each agent's sums added in list order. The switch is on by default and
// exists so tests can compare both; where the build or the processor lacks AVX-512 it has no effect.
#if defined(__x86_64__) && defined(__GNUC__)
#define KF_FLOCK_AVX512 1
// What the eight-wide code is compiled for; fp-contract=off keeps every product and sum rounded as the
// scalar code rounds it.
#define KF_EIGHT_WIDE __attribute__((target("avx512f,avx512vl"), optimize("fp-contract=off")))
#endif

namespace kf {

void allow_flock_simd(bool on);
// The processor has AVX-512 (F and VL), the build can use it, and it is allowed.
bool flock_simd_enabled();

}  // namespace kf
