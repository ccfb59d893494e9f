#pragma once
// Checks of internal invariants: a failed one is a bug, not bad input. It prints the expression, both
// values it compared and where, then ends the process with kExitInternal (10).
//   CHECK(ptr != nullptr);
//   CHECK_EQ(x.size(), 3 * n);   // "src/sim/x.cpp:12: CHECK_EQ(x.size(), 3 * n) failed: 9 vs 12"
// Unlike assert they stay on in Release builds; keep them out of inner loops.
#include <sstream>
#include <string>

namespace kf::detail {

// Prints "file:line: what failed[: values]" to stderr and exits with kExitInternal.
[[noreturn]] void check_failed(const char* file, int line, const std::string& what, const std::string& values);

template <typename A, typename B>
std::string check_values(const A& a, const B& b) {
  std::ostringstream s;
  s.precision(17);
  s << a << " vs " << b;
  return s.str();
}

}  // namespace kf::detail

#define CHECK(cond) \
  ((cond) ? (void)0 : ::kf::detail::check_failed(__FILE__, __LINE__, "CHECK(" #cond ")", std::string()))

#define KF_CHECK_OP(name, op, a, b)                                                                        \
  do {                                                                                                   \
    const auto& kf_check_a_ = (a);                                                                       \
    const auto& kf_check_b_ = (b);                                                                       \
    if (!(kf_check_a_ op kf_check_b_))                                                                   \
      ::kf::detail::check_failed(__FILE__, __LINE__, #name "(" #a ", " #b ")",                           \
                                 ::kf::detail::check_values(kf_check_a_, kf_check_b_));                  \
  } while (false)

#define CHECK_EQ(a, b) KF_CHECK_OP(CHECK_EQ, ==, a, b)
#define CHECK_NE(a, b) KF_CHECK_OP(CHECK_NE, !=, a, b)
#define CHECK_LT(a, b) KF_CHECK_OP(CHECK_LT, <, a, b)
#define CHECK_LE(a, b) KF_CHECK_OP(CHECK_LE, <=, a, b)
#define CHECK_GT(a, b) KF_CHECK_OP(CHECK_GT, >, a, b)
#define CHECK_GE(a, b) KF_CHECK_OP(CHECK_GE, >=, a, b)
