// The test runner: GoogleTest's main with floating-point traps on, so an invalid operation (0/0, inf - inf,
// sqrt(-1), an ordered comparison with NaN) or a division by zero ends the test with SIGFPE where it
// happens instead of spreading a NaN that a later comparison may not catch. Threads started afterwards
// (TBB's workers, llvmpipe's) inherit the traps, so the whole process runs with them.
//
// They stay off when a selected test is in kUntrapped below, because traps are per thread and are
// inherited: once on, a library's worker threads keep them. ctest runs each test in a process of its
// own, so there every other test traps. KEYFRAME_NO_FP_TRAPS=1 turns them off everywhere.
#include <cfenv>
#include <cstdlib>
#include <gtest/gtest.h>
#include <string>
#include <vector>

namespace {

// Tests that run code computing with infinities and NaNs on purpose:
//  - Embree's BVH builds and ray traversal (the character's point queries, the cape, the ray tracer) and
//    llvmpipe's shaders (the raster back end and everything that renders): third-party code that is not
//    trap-safe (rtcCommitScene raises FE_INVALID in its builders);
//  - tests that feed NaN or overflowing controls to check that a step reports them.
const char* const kUntrapped[] = {
    "BodyQuery.*", "BodyCollider.*", "CapeSystem.*", "MeshCape.*", "*ReachableCape*", "CapeFigure.*", "FullFigures.CapeBlend*", "EmbreeBackend.*",
    "*RenderRegression.*", "MeshSequence.BothBackEndsDrawTheBodies", "Figure.*", "Clip.*", "Compare.*", "RenderRequest.*", "CameraView.*", "ViewFrames.*",
    "FlockSystem.StepReportsNonFiniteResults", "ClothStability.HugeTrialControlsGiveALargeFiniteValue",
};

// Glob match with '*' (any run) and '?' (any one character), as --gtest_filter patterns use.
bool glob(const char* p, const char* s) {
  if (*p == '\0') return *s == '\0';
  if (*p == '*') return glob(p + 1, s) || (*s != '\0' && glob(p, s + 1));
  return *s != '\0' && (*p == '?' || *p == *s) && glob(p + 1, s + 1);
}

bool matches_any(const std::string& patterns, const std::string& name) {
  size_t start = 0;
  while (start <= patterns.size()) {
    const size_t end = std::min(patterns.find(':', start), patterns.size());
    if (glob(patterns.substr(start, end - start).c_str(), name.c_str())) return true;
    start = end + 1;
  }
  return false;
}

// True when --gtest_filter selects a test listed in kUntrapped.
bool runs_untrapped_test() {
  const std::string filter = GTEST_FLAG_GET(filter);
  const size_t dash = filter.find('-');
  const std::string positive = dash == std::string::npos ? filter : filter.substr(0, dash);
  const std::string negative = dash == std::string::npos ? "" : filter.substr(dash + 1);
  const testing::UnitTest& unit = *testing::UnitTest::GetInstance();
  for (int i = 0; i < unit.total_test_suite_count(); ++i) {
    const testing::TestSuite& suite = *unit.GetTestSuite(i);
    for (int j = 0; j < suite.total_test_count(); ++j) {
      const std::string name = std::string(suite.name()) + "." + suite.GetTestInfo(j)->name();
      if (!matches_any(positive.empty() ? "*" : positive, name) || matches_any(negative, name)) continue;
      for (const char* pattern : kUntrapped)
        if (glob(pattern, name.c_str())) return true;
    }
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  const char* off = std::getenv("KEYFRAME_NO_FP_TRAPS");
  if ((!off || std::string(off) != "1") && !runs_untrapped_test()) feenableexcept(FE_INVALID | FE_DIVBYZERO);
  return RUN_ALL_TESTS();
}
