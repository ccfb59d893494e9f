// schedule.bin (opt/schedule_file.h): the split pattern a run held, stored beside its controls and read back to
// the same pattern, so the controls simulate to the same rollout bit for bit; anything else is refused in one line
// naming the file.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>

#include "core/error.h"
#include "opt/problem.h"
#include "opt/schedule_file.h"
#include "scene/scene.h"
#include "sim/cloth/cloth_split_pattern.h"
#include "sim/make_system.h"
#include "../sim/split_curtain.h"

namespace kf {
namespace {
namespace fs = std::filesystem;

// The curtain of tests/sim/split_curtain.h, its free edge keyframed.
Scene curtain() { return test::split_curtain("", "[40, 41, 42, 43, 44, 45, 46, 47]"); }

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& p, const std::string& b) { std::ofstream(p, std::ios::binary) << b; }

// The curtain simulated once under random forces (the energy check choosing its splits), its schedule saved.
class ScheduleFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("keyframe_schedule_file_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::srand(5);
    z = problem.initial_guess() + 0.3 * problem.control_scale() * VecX::Random(problem.size());
    phi = problem.evaluate(z, nullptr);
    end = problem.rollout().x.back();
    schedule = sys->step_schedule();
    save_schedule(file(), schedule, z, scene.time.substeps, scene.time.steps());
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path file() const { return dir / "schedule.bin"; }
  // The message load_schedule refuses the file with ("" when it loads).
  std::string refusal(const Scene& s) const {
    try {
      load_schedule(file(), s, z, s.time.substeps);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  std::string refusal() const { return refusal(scene); }

  const Scene scene = curtain();
  std::unique_ptr<System> sys = make_system(scene);
  Problem problem{scene, scene.time, *sys};
  VecX z, end;
  double phi = 0;
  StepSchedule schedule;
  fs::path dir;
};

TEST_F(ScheduleFile, LoadsThePatternItWasSavedFromAndReplaysItBitForBit) {
  const ClothSystem::StepSchedule* saved = cloth_split_steps(schedule);
  ASSERT_NE(saved, nullptr);
  ASSERT_GT(test::split_steps(*saved), 2) << "the curtain should need split steps";
  const StepSchedule loaded = load_schedule(file(), scene, z, scene.time.substeps);
  ASSERT_NE(cloth_split_steps(loaded), nullptr);
  EXPECT_EQ(*cloth_split_steps(loaded), *saved);
  // Held by a fresh system, the controls land where the run that recorded it did.
  auto fresh = make_system(scene);
  Problem replay(scene, scene.time, *fresh);
  fresh->hold_step_schedule(loaded);
  EXPECT_EQ(replay.evaluate(z, nullptr), phi);
  EXPECT_EQ(replay.rollout().x.back(), end);
}

TEST_F(ScheduleFile, NoScheduleWritesNoFileAndRemovesAStaleOne) {
  save_schedule(file(), StepSchedule{}, z, scene.time.substeps, scene.time.steps());
  EXPECT_FALSE(fs::exists(file()));
  EXPECT_TRUE(load_schedule(file(), scene, z, scene.time.substeps).empty());
}

TEST_F(ScheduleFile, RefusesTruncatedCorruptAndHugeFilesInOneLineNamingTheFile) {
  const std::string good = read_bytes(file());
  const std::string name = file().string() + ": ";
  write_bytes(file(), good.substr(0, good.size() - 3));
  EXPECT_EQ(refusal().rfind(name + "truncated or oversized step schedule", 0), 0u) << refusal();
  write_bytes(file(), good.substr(0, 20));
  EXPECT_EQ(refusal(), name + "truncated step schedule (header)");
  write_bytes(file(), "KFCTRL01" + good.substr(8));
  EXPECT_EQ(refusal(), name + "not a keyframe step schedule (bad magic)");
  std::string b = good;
  b[8] = 2;  // version
  write_bytes(file(), b);
  EXPECT_EQ(refusal(), name + "step schedule version 2, expected 1");
  b = good;
  std::memset(&b[16], 0xff, 4);  // 4294967295 steps claimed
  write_bytes(file(), b);
  EXPECT_EQ(refusal().rfind(name + "truncated or oversized step schedule (4294967295 steps", 0), 0u) << refusal();
  b = good;
  std::memset(&b[28], 0xff, 8);  // 2^64 - 1 depths claimed
  write_bytes(file(), b);
  EXPECT_EQ(refusal().rfind(name + "truncated or oversized step schedule", 0), 0u) << refusal();
  b = good;
  b.back() = char(9);  // the last step's last substep deeper than its pattern tiles (max_halvings 8)
  write_bytes(file(), b);
  EXPECT_EQ(refusal().rfind(name + "corrupt step schedule: step 11's substeps do not tile it", 0), 0u) << refusal();
  b = good;
  const std::uint32_t more = 3;  // step 0's count raised: the counts no longer add up to the depths stored
  std::memcpy(&b[36], &more, 4);
  write_bytes(file(), b);
  EXPECT_EQ(refusal(), name + "corrupt step schedule (its steps' substeps do not add up)");
  write_bytes(file(), good);
  EXPECT_EQ(refusal(), "");
}

TEST_F(ScheduleFile, RefusesTheScheduleOfOtherControlsOrAnotherStepLength) {
  const std::string name = file().string() + ": ";
  VecX other = z;
  other[3] = std::nextafter(other[3], 1e300);  // one bit
  EXPECT_THROW(load_schedule(file(), scene, other, scene.time.substeps), InputError);
  try {
    load_schedule(file(), scene, other, scene.time.substeps);
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), name +
                                         "the step schedule of other controls than those beside it (remove it to "
                                         "choose the schedule anew)");
  }
  Scene finer = scene;
  finer.time.substeps = 2;
  EXPECT_EQ(refusal(finer), name + "a step schedule of 12 steps at 1 substeps; the controls are for 24 at 2");
  const Scene flock = parse_scene(R"({"time": {"frames": 12}, "flock": {"agents": 3},
    "objectives": [{"type": "center_of_mass", "frame": 12, "target": [1, 0, 2]}]})",
                                  "flock.json");
  EXPECT_EQ(refusal(flock), name + "a step schedule, but the scene has no cloth to hold it");
}

TEST_F(ScheduleFile, RefusesAFifoWithoutOpeningIt) {
  fs::remove(file());
  ASSERT_EQ(::mkfifo(file().c_str(), 0600), 0);
  EXPECT_EQ(refusal(), file().string() + ": not a regular file");
}

TEST(SplitPattern, TilesAStepInOrderWithinTheHalvings) {
  using P = std::vector<std::uint8_t>;
  for (const P& ok : {P{}, P{0}, P{1, 1}, P{1, 2, 2}, P{2, 2, 1}, P{2, 3, 3, 1}, P{8, 8, 7, 6, 5, 4, 3, 2, 1}})
    EXPECT_TRUE(is_split_pattern(ok, 8)) << ::testing::PrintToString(ok);
  for (const P& bad : {P{1}, P{0, 0}, P{1, 1, 1}, P{2, 1, 2}, P{0, 1}, P{9, 9, 8, 7, 6, 5, 4, 3, 2, 1}})
    EXPECT_FALSE(is_split_pattern(bad, 8)) << ::testing::PrintToString(bad);
  EXPECT_FALSE(is_split_pattern({1, 1}, 0));
}

}  // namespace
}  // namespace kf
