// Keyframe targets as an offset from where the particles would be without controls ("from":
// "uncontrolled"), through the real binary: the target is the uncontrolled position at the keyframe's frame
// plus the offset, so the dry run misses each keyframe by exactly the offset; the run directory's scene.json
// holds the resolved targets (what render and resume read); errors name the key.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "core/trajectory.h"
#include "../support/cli_test.h"

namespace kf {
namespace {
using namespace cli_test;

class UncontrolledOffsetCli : public TempDirTest {};

// A 6 x 5 curtain pinned along its top edge, released flat and swinging down. cg_tolerance is stated, so
// simulate's trajectory is computed as the optimiser's (and the resolution's) is, to round-off.
std::string curtain(const std::string& objectives, const std::string& optimizer = "{}") {
  return R"({"seed": 2, "time": {"fps": 30, "frames": 12},
  "cloth": {"nx": 6, "ny": 5, "width": 0.5, "height": 0.4, "origin": [-0.25, 1, 0], "u_axis": [1, 0, 0],
            "v_axis": [0, 0, -1], "pins": "top_edge", "cg_tolerance": 1e-10},
  "objectives": [)" + objectives + R"(],
  "controls": {"kind": "per_frame"}, "optimizer": )" + optimizer + R"(,
  "render": {"width": 64, "height": 48}})";
}

const char* kBottomEdgeBack = R"({"type": "position", "frame": 10, "particles": "bottom_edge",
                                  "offset": [0, 0.12, -0.05], "from": "uncontrolled"})";
const char* kCentreUp = R"({"type": "center_of_mass", "frame": 12, "particles": {"row": 2},
                            "offset": [0.03, 0.04, 0], "from": "uncontrolled"})";

Vec3 at(const VecX& x, int i) { return x.segment<3>(3 * i); }
Vec3 point(const Json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

TEST_F(UncontrolledOffsetCli, TheDryRunMissesEachKeyframeByItsOffsetAndTheRunKeepsTheResolvedTargets) {
  write("curtain.json", curtain(std::string(kBottomEdgeBack) + ", " + kCentreUp, R"({"max_evaluations": 10})"));
  const auto r = run_keyframe("simulate curtain.json --out run", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  const Json report = Json::parse(read_text(dir_ / "run/report.json"));
  ASSERT_EQ(report["measures"].size(), 2u) << report.dump();
  // A rigid offset: every particle of the edge misses by its length, so the RMS is that length.
  EXPECT_NEAR(report["measures"][0]["rms_error"].get<double>(), std::hypot(0.12, 0.05), 1e-9) << report.dump();
  EXPECT_NEAR(report["measures"][1]["error"].get<double>(), std::hypot(0.03, 0.04), 1e-9) << report.dump();
  EXPECT_NE(r.output.find("center_of_mass@12: 5.00 cm from its target"), std::string::npos) << r.output;

  // The run's scene.json names the targets themselves: the uncontrolled positions plus the offset.
  const Trajectory t = load_trajectory(dir_ / "run/trajectory.bin");
  const Json scene = Json::parse(read_text(dir_ / "run/scene.json"));
  const Json& edge = scene["objectives"][0];
  EXPECT_FALSE(edge.contains("offset") || edge.contains("from")) << edge.dump();
  ASSERT_EQ(edge["targets"].size(), 6u) << edge.dump();
  for (int i = 0; i < 6; ++i)  // the bottom edge is row 0: particles 0..5
    EXPECT_LT((point(edge["targets"][size_t(i)]) - (at(t.x[10], i) + Vec3(0, 0.12, -0.05))).norm(), 1e-12) << i;
  Vec3 mean = Vec3::Zero();
  for (int i = 12; i < 18; ++i) mean += at(t.x[12], i) / 6.0;
  EXPECT_LT((point(scene["objectives"][1]["target"]) - (mean + Vec3(0.03, 0.04, 0))).norm(), 1e-12);

  // optimize resolves the same targets before it starts, and writes them into its own run directory.
  const auto o = run_keyframe("optimize curtain.json --out opt", dir_);
  ASSERT_TRUE(o.code == 0 || o.code == 7) << o.output;
  const Json optimized = Json::parse(read_text(dir_ / "opt/scene.json"));
  EXPECT_EQ(optimized["objectives"], scene["objectives"]);
  const Json opt_report = Json::parse(read_text(dir_ / "opt/report.json"));
  // Its miss before optimising (in tolerances of 1 cm) is the offset's length.
  EXPECT_NEAR(opt_report["keyframe_errors"][0]["miss_before"].get<double>(), 100 * std::hypot(0.12, 0.05), 1e-6)
      << opt_report["keyframe_errors"].dump();
}

// A flock's agents have no rest sheet but have an uncontrolled motion: agent 0 two metres to the side of
// where it would be.
TEST_F(UncontrolledOffsetCli, AFlockAgentOffsetFromWhereItWouldBe) {
  write("flock.json", R"({"seed": 3, "time": {"fps": 30, "frames": 20},
    "flock": {"agents": 12, "spawn": {"radius": 3, "velocity": [0, 0, 1]}},
    "objectives": [{"type": "position", "frame": 15, "particles": [0], "offset": [2, 0, 0], "from": "uncontrolled"}]})");
  const auto r = run_keyframe("simulate flock.json --out run", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  const Json report = Json::parse(read_text(dir_ / "run/report.json"));
  EXPECT_NEAR(report["measures"][0]["rms_error"].get<double>(), 2.0, 1e-12) << report.dump();
}

TEST_F(UncontrolledOffsetCli, BadOffsetsAreOneLineNamingTheKey) {
  const auto error_of = [&](const std::string& text) {
    write("bad.json", text);
    const auto r = run_keyframe("simulate bad.json --out bad", dir_);
    EXPECT_NE(r.code, 0) << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "bad")) << "partial output";
    return r.output;
  };
  EXPECT_NE(error_of(curtain(R"({"type": "position", "frame": 5, "particles": "bottom_edge", "offset": [0, 1, 0],
                                 "from": "unaided"})"))
                .find("bad.json: /objectives/0/from: expected one of \"rest\", \"uncontrolled\""),
            std::string::npos);
  EXPECT_NE(error_of(curtain(R"({"type": "position", "frame": 5, "particles": {"row": 0}, "offset": [[0, 1, 0], [0, 2, 0]],
                                 "from": "uncontrolled"})"))
                .find("bad.json: /objectives/0/offset: expected [dx, dy, dz] (the whole set moved rigidly) or one "
                      "offset per particle (6), got 2"),
            std::string::npos);
  EXPECT_NE(error_of(curtain(R"({"type": "center_of_mass", "frame": 5, "target": [0, 0, 0], "offset": [0, 1, 0],
                                 "from": "uncontrolled"})"))
                .find("bad.json: /objectives/0/offset: expected either \"target\" or \"offset\", not both"),
            std::string::npos);
  // A selector that matches nothing is named before any simulation.
  EXPECT_NE(error_of(curtain(R"({"type": "position", "frame": 5, "particles": {"row": 9}, "offset": [0, 1, 0],
                                 "from": "uncontrolled"})"))
                .find("bad.json: /objectives/0/particles"),
            std::string::npos);
  const std::string flock = R"({"time": {"frames": 10}, "flock": {"agents": 4},
    "objectives": [{"type": "center_of_mass", "frame": 5, "offset": [1, 0.5, 0], "from": "uncontrolled"}]})";
  EXPECT_NE(error_of(flock).find("bad.json: /objectives/0/offset: expected an offset along the ground, dy = 0"),
            std::string::npos);
}

}  // namespace
}  // namespace kf
