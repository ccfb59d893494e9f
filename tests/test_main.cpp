// The test runner: GoogleTest's main with floating-point traps on, so an invalid operation (0/0, inf - inf,
// sqrt(-1)) or a division by zero anywhere in a test ends it with SIGFPE at the operation instead of
// spreading a NaN that a later comparison may not catch. Threads started afterwards (TBB's workers)
// inherit the traps. KEYFRAME_NO_FP_TRAPS=1 turns them off, e.g. to see where a NaN ends up.
#include <cfenv>
#include <cstdlib>
#include <string>
#include <gtest/gtest.h>

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  const char* off = std::getenv("KEYFRAME_NO_FP_TRAPS");
  if (!off || std::string(off) != "1") feenableexcept(FE_INVALID | FE_DIVBYZERO);
  return RUN_ALL_TESTS();
}
