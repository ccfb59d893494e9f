// The thread count changes speed only: optimising and rendering a scene with one worker thread and with
// two gives byte-identical trajectories, controls and frames.
#include "cli_harness.h"
#include "app/optimize_job.h"
#include "core/error.h"

namespace kf::reliability {
namespace {

class Determinism : public TempDirTest {
 protected:
  // Optimises and renders `scene` with `threads` workers into run directory `out`.
  void optimise_and_render(const std::string& scene, int threads, const std::string& out,
                           const std::string& backend) {
    const std::string t = "--threads " + std::to_string(threads) + " ";
    CliResult r = run_keyframe(t + "optimize " + scene + " --quiet --out " + out, dir_);
    // These few evaluations do not reach the keyframes (exit 7); the bits are what is compared.
    ASSERT_TRUE(r.code == 0 || r.code == kExitNotReached) << r.output;
    r = run_keyframe(t + "render " + out + " --backend " + backend + " --frames 0:3 --size 48x32", dir_);
    ASSERT_EQ(r.code, 0) << r.output;
  }
  void expect_same_files(const std::string& a, const std::string& b) {
    for (const char* f : {"trajectory.bin", "controls.bin", "frames/frame_0000.png", "frames/frame_0001.png",
                          "frames/frame_0002.png"}) {
      const std::string x = read_text(dir_ / a / f), y = read_text(dir_ / b / f);
      ASSERT_FALSE(x.empty()) << f;
      EXPECT_TRUE(x == y) << f << " differs between --threads 1 and --threads 2";
    }
  }
};

TEST_F(Determinism, FlockIsBitIdenticalForOneAndTwoThreads) {
  write("flock.json", small_flock_scene(20));
  optimise_and_render("flock.json", 1, "t1", "osmesa");
  optimise_and_render("flock.json", 2, "t2", "osmesa");
  expect_same_files("t1", "t2");
}

TEST_F(Determinism, ClothIsBitIdenticalForOneAndTwoThreads) {
  write("cloth.json", small_cloth_scene(10));
  optimise_and_render("cloth.json", 1, "t1", "osmesa");
  optimise_and_render("cloth.json", 2, "t2", "osmesa");
  expect_same_files("t1", "t2");
}

TEST_F(Determinism, RayTracedFramesAreBitIdenticalForOneAndTwoThreads) {
  write("flock.json", small_flock_scene(6));
  optimise_and_render("flock.json", 1, "t1", "embree");
  optimise_and_render("flock.json", 2, "t2", "embree");
  expect_same_files("t1", "t2");
}

}  // namespace
}  // namespace kf::reliability
