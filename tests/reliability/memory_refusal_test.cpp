// Memory is estimated before a run: one that cannot fit is refused at once with the estimate (exit 3,
// nothing written) instead of paging for minutes and ending in std::bad_alloc; a checkpoint spacing past
// the end of a run costs no more than keeping every state.
#include <fstream>

#include <nlohmann/json.hpp>

#include "cli_harness.h"
#include "core/error.h"

namespace kf::reliability {
namespace {

class MemoryRefusal : public TempDirTest {
 protected:
  void expect_refused(const std::string& args, const std::string& message_start) {
    const auto before = list_tree(dir_);
    const CliResult r = run_keyframe(args, dir_);
    EXPECT_EQ(r.code, kExitInput) << r.output;
    EXPECT_EQ(r.output.rfind("keyframe: error: " + message_start, 0), 0u) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_EQ(list_tree(dir_), before);
  }
};

TEST_F(MemoryRefusal, ClothTooLargeForTheMachineIsRefusedUpFront) {
  // 1024 x 1024 particles for 10,000 frames: 469 GiB of frame states alone (it used to run out of memory
  // after minutes with "internal error: std::bad_alloc").
  write("c.json", R"({"time": {"frames": 10000}, "cloth": {"nx": 1024, "ny": 1024}})");
  expect_refused("simulate c.json",
                 "c.json: needs at least 937.6 GiB of memory (frame states 468.8 GiB + trajectory 468.8 GiB), more "
                 "than the machine's ");
  expect_refused("optimize c.json --quiet", "c.json: needs at least ");
}

TEST_F(MemoryRefusal, MaxMemoryIsALimitTheEstimateIsHeldTo) {
  write("f.json", small_flock_scene(6));
  expect_refused("simulate f.json --max-memory 1K",
                 "f.json: needs at least 7.9 KiB of memory (frame states 3.9 KiB + trajectory 3.9 KiB), more than "
                 "--max-memory 1.0 KiB; shorten the run, use fewer particles or set optimizer.checkpoint_every");
  expect_refused("simulate f.json --max-memory lots",
                 "--max-memory: expected a size such as 4G, 512M or 1.5GiB, got \"lots\"");
  EXPECT_EQ(run_keyframe("simulate f.json --max-memory 1M", dir_).code, 0);
  // The fuzz corpus's million agents: refused at once under a 1 GiB limit (it took 85 s and 5.7 GB before).
  write("big.json", R"({"flock": {"spawn": {"radius": 1e6}, "agents": 1000000}})");
  expect_refused("simulate big.json --max-memory 1G", "big.json: needs at least 9.0 GiB of memory");
}

TEST_F(MemoryRefusal, OptimizeTakesMaxMemoryInTheFormSimulateTakes) {
  // The same size text as simulate's; for optimize it is the budget that picks the checkpoint spacing.
  write("f.json", small_flock_scene(6));
  expect_refused("optimize f.json --quiet --max-memory lots",
                 "--max-memory: expected a size such as 4G, 512M or 1.5GiB, got \"lots\"");
  const auto budget_of = [&](const std::string& size, const std::string& out) {
    const CliResult r = run_keyframe("optimize f.json --quiet --max-memory " + size + " --out " + out, dir_);
    EXPECT_TRUE(r.code == 0 || r.code == 7) << r.output;
    std::ifstream in(dir_ / out / "report.json");
    return in ? nlohmann::json::parse(in) : nlohmann::json{};
  };
  // The budget is the whole process's: its code and libraries count too.
  const nlohmann::json roomy = budget_of("1.5G", "roomy"), tight = budget_of("1K", "tight");
  ASSERT_TRUE(roomy.contains("memory_budget_gb") && tight.contains("memory_budget_gb"));
  EXPECT_DOUBLE_EQ(roomy.at("memory_budget_gb").get<double>(), 1.5 * 1073741824 / 1e9);
  EXPECT_EQ(roomy.at("checkpoint_every_for_budget").get<int>(), 0);  // every step fits in 1.5 GiB
  EXPECT_DOUBLE_EQ(tight.at("memory_budget_gb").get<double>(), 1024 / 1e9);
  EXPECT_GT(tight.at("checkpoint_every_for_budget").get<int>(), 0);  // 1 KiB does not: checkpointed
  // 0 is each command's default.
  EXPECT_EQ(run_keyframe("simulate f.json --max-memory 0 --out sim", dir_).code, 0);
  EXPECT_GT(budget_of("0", "default").at("memory_budget_gb").get<double>(), 0.01);
}

TEST_F(MemoryRefusal, CheckpointSpacingPastTheEndCostsNoMoreThanKeepingEveryState) {
  // 20 agents, 10 steps: a spacing of 10^7 once asked for 10^7 states (12.7 GB); under a 3 GB address-space
  // limit it must now finish.
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space for its shadow memory, so no "
                  "address-space limit (ulimit -v) can be set under it; the Release suite runs this test";
#endif
  write("f.json", R"({"seed": 3, "time": {"frames": 10}, "flock": {"agents": 20, "spawn": {"radius": 3}},
    "objectives": [{"type": "center_of_mass", "frame": 10, "target": [1, 0, 2]}],
    "optimizer": {"max_evaluations": 3}})");
  const std::string cmd = "cd '" + dir_.string() + "' && ulimit -v 3000000 && '" KEYFRAME_BINARY
                          "' --threads 1 optimize f.json --quiet --checkpoint-every 10000000 --out run 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  const int status = pclose(p);
  // Three evaluations do not reach the keyframe (exit 7): the run is written all the same.
  EXPECT_TRUE(WIFEXITED(status) && (WEXITSTATUS(status) == 0 || WEXITSTATUS(status) == 7)) << out;
  EXPECT_TRUE(fs::exists(dir_ / "run/controls.bin")) << out;
}

}  // namespace
}  // namespace kf::reliability
