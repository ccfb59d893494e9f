// No keyframe ends farther off than uncontrolled (opt/uncontrolled_floor.h), through `keyframe optimize`'s job
// on the reduced generated drops onto a collider with friction (two or three keyframes each; about half of them
// end at their budget with a keyframe unmet). At full size drop-collider-3 left its centre of mass @13 at
// 11.75 cm against 3.95 cm uncontrolled.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/optimize_job.h"
#include "bench/bench_reachable.h"
#include "../sim/character_test_util.h"

namespace kf {
namespace {

using nlohmann::json;

void expect_no_keyframe_worse_than_uncontrolled(int index) {
  test::TempDir dir;
  const ReachableScene r = generate_reachable("drop-collider", 52, index, true, dir.path());
  ASSERT_TRUE(r.friction);
  std::ofstream(dir.path() / "scene.json") << r.scene.dump(1);
  OptimizeOptions opt;
  opt.quiet = true;
  opt.out = (dir.path() / "run").string();
  optimize_job(dir.path() / "scene.json", opt);
  std::ifstream in(dir.path() / "run" / "report.json");
  const json report = json::parse(in);
  ASSERT_EQ(report.at("keyframe_errors").size(), std::size_t(r.keyframes));
  for (const json& k : report.at("keyframe_errors")) {
    if (!k.at("met").get<bool>()) {
      EXPECT_LE(k.at("miss_after").get<double>(), k.at("miss_before").get<double>() * (1 + 1e-9)) << k.dump();
    }
  }
  if (report.contains("fallback")) {  // a run that fell back says so in its diagnosis
    const std::string why = report.at("fallback").get<std::string>();
    EXPECT_NE(why.find("farther off than uncontrolled"), std::string::npos) << why;
    EXPECT_NE(report.at("diagnosis").at("diagnosis").get<std::string>().find(why), std::string::npos);
  }
  std::printf("drop-collider-%d: %s\n", index, report.contains("fallback") ? "fell back" : "kept its result");
}

TEST(UncontrolledFloorJob, ReducedFrictionDropsEndNoKeyframeWorseThanUncontrolled) {
  for (int index : {1, 3, 5, 7, 9, 11}) expect_no_keyframe_worse_than_uncontrolled(index);
}

}  // namespace
}  // namespace kf
