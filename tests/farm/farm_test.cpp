// keyframe farm without a cluster: the scripts it writes, what it submits (through a stand-in sbatch that
// records its calls), resubmission, bad input, and the scripts run by hand as Slurm would run each task.
#include <regex>

#include "../reliability/cli_harness.h"
#include "core/error.h"
#include "render/clip/make_clip.h"

namespace kf::reliability {
namespace {

class Farm : public TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    // Stand-ins for sbatch and scancel: they log their arguments; sbatch prints job ids 101, 102, ...
    // and fails on call number $FAIL_AT.
    fs::create_directories(dir_ / "bin");
    write("bin/sbatch", "#!/bin/sh\necho \"$*\" >> \"" + (dir_ / "sbatch.log").string() + "\"\n"
                        "n=$(wc -l < \"" + (dir_ / "sbatch.log").string() + "\")\n"
                        "if [ \"$n\" = \"${FAIL_AT:-0}\" ]; then\n"
                        "  echo 'sbatch: error: invalid account' >&2; exit 1\nfi\n"
                        "echo $((100 + n))\n");
    write("bin/scancel", "#!/bin/sh\necho \"$*\" >> \"" + (dir_ / "scancel.log").string() + "\"\n");
    fs::permissions(dir_ / "bin/sbatch", fs::perms::owner_all);
    fs::permissions(dir_ / "bin/scancel", fs::perms::owner_all);
    write("scene.json", small_flock_scene(11));
    ASSERT_EQ(run_keyframe("simulate scene.json --out run", dir_).code, 0);
  }
  // keyframe ARGS with the stand-in sbatch first on PATH (or no Slurm at all).
  CliResult farm(const std::string& args, const std::string& env = "", bool slurm = true) {
    const std::string path = slurm ? (dir_ / "bin").string() + ":/usr/bin:/bin" : "/nonexistent";
    return run_keyframe_env("PATH='" + path + "' " + env, "farm " + args);
  }
  CliResult run_keyframe_env(const std::string& env, const std::string& args) {
    FILE* p = popen(("cd '" + dir_.string() + "' && " + env + " '" KEYFRAME_BINARY "' " + args + " 2>&1").c_str(), "r");
    std::string out;
    char buf[4096];
    while (size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
    const int status = pclose(p);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
  }
  // Runs a written script as Slurm would run array task `task`.
  CliResult run_script(const fs::path& script, int task = 0) {
    FILE* p = popen(("cd '" + dir_.string() + "' && SLURM_ARRAY_TASK_ID=" + std::to_string(task) + " bash '" +
                     script.string() + "' 2>&1")
                        .c_str(),
                    "r");
    std::string out;
    char buf[4096];
    while (size_t n = fread(buf, 1, sizeof buf, p)) out.append(buf, n);
    const int status = pclose(p);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
  }
  std::string sbatch_calls() { return read_text(dir_ / "sbatch.log"); }
  int frames() { return 12; }  // small_flock_scene(11): frames 0..11
};

int count_lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

TEST_F(Farm, DryRunPrintsShortScriptsAndWritesNothing) {
  const auto before = list_tree(dir_);
  const CliResult r = farm("render run --chunk 5 --size 64x48 --backend embree --spp 4 --dry-run --partition gpu "
                           "--time 1:00:00 --sbatch=--qos=high");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(list_tree(dir_), before) << "a dry run writes nothing";
  EXPECT_TRUE(sbatch_calls().empty()) << "a dry run submits nothing";
  const std::vector<std::string> expected = {
      "#SBATCH --job-name=keyframe-render-run\n", "#SBATCH --array=0-2\n", "#SBATCH --partition=gpu\n",
      "#SBATCH --time=1:00:00\n", "#SBATCH --qos=high\n", "chunks=(0:5 5:10 10:12)\n",
      "run=" + (dir_ / "run").string() + "\n", "render \"$run\" --frames \"${chunks[$SLURM_ARRAY_TASK_ID]}\"",
      "--backend embree --size 64x48 --spp 4\n", "#SBATCH --job-name=keyframe-check-run\n",
      "\"$keyframe\" farm check \"$run\" --frames 0:12 --size 64x48\n",
      "# sbatch --dependency=afterok:JOBID " + (dir_ / "run/farm/check.sbatch").string() + "\n"};
  for (const auto& line : expected)
    EXPECT_NE(r.output.find(line), std::string::npos) << "missing: " << line << "\n" << r.output;
  EXPECT_LE(count_lines(r.output), 40) << r.output;  // two scripts of under 20 lines and how to submit them
}

TEST_F(Farm, SubmitsTheArrayThenTheCheckAfterIt) {
  const CliResult r = farm("render run --chunk 5 --size 64x48");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("submitted job 101 (render.sbatch) and job 102 (check.sbatch, after 101)"),
            std::string::npos)
      << r.output;
  const std::string farm_dir = (dir_ / "run/farm").string();
  EXPECT_EQ(sbatch_calls(), "--parsable " + farm_dir + "/render.sbatch\n--parsable --dependency=afterok:101 " +
                                farm_dir + "/check.sbatch\n");
  EXPECT_TRUE(fs::is_directory(dir_ / "run/farm/logs"));
  EXPECT_NE(read_text(dir_ / "run/farm/render.sbatch").find("chunks=(0:5 5:10 10:12)\n"), std::string::npos);
}

TEST_F(Farm, RefusedFollowUpCancelsTheArray) {
  const CliResult r = farm("render run --chunk 5", "FAIL_AT=2");
  EXPECT_EQ(r.code, kExitOutput) << r.output;
  EXPECT_NE(r.output.find("sbatch: error: invalid account"), std::string::npos) << r.output;
  EXPECT_EQ(count_lines(r.output), 1) << r.output;
  EXPECT_EQ(read_text(dir_ / "scancel.log"), "101\n");
}

TEST_F(Farm, ResubmissionRendersOnlyMissingOrBrokenFrames) {
  ASSERT_EQ(run_keyframe("render run --size 64x48", dir_).code, 0);
  fs::remove(dir_ / "run/frames/frame_0005.png");
  write("run/frames/frame_0009.png", read_text(dir_ / "run/frames/frame_0009.png").substr(0, 100));  // torn
  CliResult r = farm("render run --chunk 5 --size 64x48 --dry-run");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("10 of 12 frames already complete (skipped)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("chunks=(5:6 9:10)\n"), std::string::npos) << r.output;
  // Frames of another size are not complete either.
  r = farm("render run --chunk 5 --size 32x24 --dry-run");
  EXPECT_NE(r.output.find("chunks=(0:5 5:10 10:12)\n"), std::string::npos) << r.output;
  // The check job's command names the broken frames.
  r = run_keyframe("farm check run --size 64x48", dir_);
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_NE(r.output.find("2 of 12 frames not complete (frame_0005.png missing, frame_0009.png not a readable PNG)"),
            std::string::npos)
      << r.output;
  // Once every frame is there, nothing is submitted.
  ASSERT_EQ(run_keyframe("render run --size 64x48 --frames 5:10", dir_).code, 0);
  r = farm("render run --chunk 5 --size 64x48");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("all 12 frames of " + (dir_ / "run").string() + " are complete; nothing to submit"),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(sbatch_calls().empty());
}

TEST_F(Farm, ScriptsRunByHandMakeTheLocalFrames) {
  fs::copy(dir_ / "run", dir_ / "local", fs::copy_options::recursive);
  ASSERT_EQ(run_keyframe("render local --size 48x32", dir_).code, 0);
  ASSERT_EQ(farm("render run --chunk 5 --size 48x32").code, 0);
  for (int task = 0; task < 3; ++task) {
    const CliResult r = run_script(dir_ / "run/farm/render.sbatch", task);
    ASSERT_EQ(r.code, 0) << r.output;
  }
  const CliResult r = run_script(dir_ / "run/farm/check.sbatch");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("all 12 frames of"), std::string::npos) << r.output;
  for (int f = 0; f < frames(); ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.png", f);
    EXPECT_EQ(read_text(dir_ / "run/frames" / name), read_text(dir_ / "local/frames" / name)) << name;
  }
}

TEST_F(Farm, TurntableViewsAreSharedOutAndMatchAWholeTurntable) {
  CliResult r = farm("render run --turntable 7 --chunk 3 --size 32x24 --frames 4 --dry-run");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("chunks=(0:3 3:6 6:7)\n"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--frames 4 --turntable 7 --views \"${chunks[$SLURM_ARRAY_TASK_ID]}\""), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("farm check \"$run\" --turntable 7 --size 32x24\n"),
            std::string::npos)
      << r.output;
  // A share of the views is the same images as the whole turntable's.
  fs::copy(dir_ / "run", dir_ / "whole", fs::copy_options::recursive);
  ASSERT_EQ(run_keyframe("render whole --turntable 7 --frames 4 --size 32x24", dir_).code, 0);
  r = run_keyframe("render run --turntable 7 --frames 4 --size 32x24 --views 3:5", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(list_tree(dir_ / "run/frames"), (std::vector<std::string>{"turntable_0003.png", "turntable_0004.png"}));
  for (const char* name : {"turntable_0003.png", "turntable_0004.png"})
    EXPECT_EQ(read_text(dir_ / "run/frames" / name), read_text(dir_ / "whole/frames" / name)) << name;
  r = run_keyframe("render run --turntable 7 --views 6:9", dir_);
  EXPECT_EQ(r.code, kExitInput) << r.output;
}

TEST_F(Farm, SweepScriptsRunByHandGatherIntoOneCsv) {
  CliResult r = farm("optimize scene.json --sweep /controls/alpha=0.01,0.1 --sweep /optimizer/max_evaluations=3,5 "
                     "--out sweep");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string sweep = (dir_ / "sweep").string();
  EXPECT_EQ(sbatch_calls(), "--parsable " + sweep + "/farm/optimize.sbatch\n--parsable --dependency=afterany:101 " +
                                sweep + "/farm/gather.sbatch\n");
  const std::string script = read_text(dir_ / "sweep/farm/optimize.sbatch");
  EXPECT_NE(script.find("#SBATCH --job-name=keyframe-optimize-sweep\n#SBATCH --array=0-3\n"), std::string::npos)
      << script;
  EXPECT_NE(script.find("runs=(scene_alpha=0.01_max_evaluations=3 scene_alpha=0.01_max_evaluations=5 "
                        "scene_alpha=0.1_max_evaluations=3 scene_alpha=0.1_max_evaluations=5)\n"),
            std::string::npos)
      << script;
  for (int task = 0; task < 4; ++task) {
    r = run_script(dir_ / "sweep/farm/optimize.sbatch", task);
    ASSERT_EQ(r.code, 0) << r.output;
  }
  r = run_script(dir_ / "sweep/farm/gather.sbatch");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string csv = read_text(dir_ / "sweep/sweep.csv");
  EXPECT_EQ(count_lines(csv), 5) << csv;
  EXPECT_EQ(csv.rfind("run,scene,/controls/alpha,/optimizer/max_evaluations,evaluations,", 0), 0u) << csv;
  EXPECT_NE(csv.find("\nscene_alpha=0.1_max_evaluations=5,scene,0.1,5,"), std::string::npos) << csv;
  EXPECT_EQ(fs::exists(dir_ / "sweep/sweep.png"), !render::find_program("gnuplot").empty());
  // The point's value reached the run: its scene copy has it.
  EXPECT_NE(read_text(dir_ / "sweep/scene_alpha=0.1_max_evaluations=3/scene.json").find("\"max_evaluations\": 3"),
            std::string::npos);
  // Finished runs are skipped; a deleted one is the only one submitted again.
  fs::remove_all(dir_ / "sweep/scene_alpha=0.01_max_evaluations=5");
  r = farm("optimize scene.json --sweep /controls/alpha=0.01,0.1 --sweep /optimizer/max_evaluations=3,5 --out sweep "
           "--dry-run");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("3 of 4 runs already finished (skipped)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("runs=(scene_alpha=0.01_max_evaluations=5)\n"), std::string::npos) << r.output;
  // Gathering now reports the missing run and still writes its row.
  r = run_keyframe("farm gather sweep", dir_);
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_NE(r.output.find("1 run did not finish (scene_alpha=0.01_max_evaluations=5)"), std::string::npos) << r.output;
  EXPECT_NE(read_text(dir_ / "sweep/sweep.csv").find("not finished"), std::string::npos);
}

// Bad input: one line, its exit code, nothing submitted, nothing written.
struct BadFarm {
  const char* name;
  std::string args;
  int code;
  std::string message;  // expected output after "keyframe: error: " (whole line)
  bool slurm = true;    // false: no sbatch on PATH
};

void PrintTo(const BadFarm& c, std::ostream* os) { *os << c.name; }

class FarmBadInput : public Farm, public ::testing::WithParamInterface<BadFarm> {};

TEST_P(FarmBadInput, OneLineNothingSubmittedNothingWritten) {
  const BadFarm& c = GetParam();
  fs::create_directories(dir_ / "bare");
  write("bare/scene.json", small_flock_scene(11));  // a run directory without a trajectory
  const auto before = list_tree(dir_);
  const CliResult r = farm(c.args, "", c.slurm);
  EXPECT_EQ(r.code, c.code) << r.output;
  std::string message = c.message;
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"$DIR", dir_.string()}})
    for (size_t at; (at = message.find(from)) != std::string::npos;) message.replace(at, from.size(), to);
  EXPECT_EQ(r.output, "keyframe: error: " + message + "\n");
  EXPECT_TRUE(sbatch_calls().empty()) << sbatch_calls();
  EXPECT_EQ(list_tree(dir_), before);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, FarmBadInput,
    ::testing::Values(
        BadFarm{"NoSlurmRender", "render run", kExitInput,
                "no Slurm here: sbatch is not on PATH (install Slurm's client commands, e.g. Debian's slurm-client, "
                "or use --dry-run to print the scripts); nothing submitted",
                false},
        BadFarm{"NoSlurmOptimize", "optimize scene.json --sweep /controls/alpha=1,2", kExitInput,
                "no Slurm here: sbatch is not on PATH (install Slurm's client commands, e.g. Debian's slurm-client, "
                "or use --dry-run to print the scripts); nothing submitted",
                false},
        BadFarm{"NoTrajectory", "render bare", kExitInput,
                "$DIR/bare: no trajectory.bin to render (run 'keyframe simulate' or 'keyframe run' first)"},
        BadFarm{"NotARunDirectory", "render nowhere", kExitInput, "$DIR/nowhere: not a run directory (does not exist)"},
        BadFarm{"ChunkZero", "render run --chunk 0", kExitInput, "--chunk: expected at least 1 frame per task, got 0"},
        BadFarm{"FramesOutOfRange", "render run --frames 5:40", kExitInput,
                "--frames 5:40 out of range: $DIR/run has frames 0..11 (A:B renders A..B-1)"},
        BadFarm{"UnknownBackend", "render run --backend povray", kExitInput,
                "unknown render back end \"povray\" (expected one of: osmesa, embree)"},
        BadFarm{"SbatchOptionNotAnOption", "render run --sbatch=qos", kExitInput,
                "--sbatch: expected one sbatch option such as --qos=high, got \"qos\""},
        BadFarm{"SweepKeyNotInScene", "optimize scene.json --sweep /flock/agentz=10,12", kExitInput,
                "--sweep /flock/agentz=10: scene.json: /flock/agentz: unknown key (check its spelling; see README "
                "'Scene files')"},
        BadFarm{"SweepBlockNotInScene", "optimize scene.json --sweep /cloth/stretch=500,2000", kExitInput,
                "--sweep /cloth/stretch: scene.json has no /cloth block to set stretch in"},
        BadFarm{"SweepValueOfWrongType", "optimize scene.json --sweep /flock/agents=12,ten", kExitInput,
                "--sweep /flock/agents=ten: scene.json has a number at /flock/agents (12), got a string"},
        BadFarm{"SweepValueOutOfRange", "optimize scene.json --sweep /flock/agents=0", kExitInput,
                "--sweep /flock/agents=0: scene.json: /flock/agents: expected an integer in [1, 1000000], got 0"},
        BadFarm{"SweepWithoutKey", "optimize scene.json --sweep alpha=1,2", kExitInput,
                "--sweep alpha=1,2: no key (expected KEY=V1,V2,... with KEY a JSON pointer into the scene, e.g. "
                "/cloth/stretch=500,2000)"},
        BadFarm{"SweepEmptyValue", "optimize scene.json --sweep /controls/alpha=1,,2", kExitInput,
                "--sweep /controls/alpha=1,,2: an empty value (expected KEY=V1,V2,... with KEY a JSON pointer into "
                "the scene, e.g. /cloth/stretch=500,2000)"},
        BadFarm{"SceneMissing", "optimize nosuch.json", kExitInput, "nosuch.json: cannot open scene file"},
        // Sweep values that do not parse: refused with the reason, never a crash.
        BadFarm{"SweepUnclosedBracket", "optimize scene.json --sweep '/flock/spawn/center=[1,0,3'", kExitInput,
                "--sweep /flock/spawn/center=[1,0,3: an unclosed [ or { (expected KEY=V1,V2,... with KEY a JSON "
                "pointer into the scene, e.g. /cloth/stretch=500,2000)"},
        BadFarm{"SweepUnclosedQuote", "optimize scene.json --sweep '/controls/kind=\"abc'", kExitInput,
                "--sweep /controls/kind=\"abc: an unclosed quote (expected KEY=V1,V2,... with KEY a JSON pointer "
                "into the scene, e.g. /cloth/stretch=500,2000)"},
        BadFarm{"SweepOpenBrace", "optimize scene.json --sweep '/controls/alpha={'", kExitInput,
                "--sweep /controls/alpha={: an unclosed [ or { (expected KEY=V1,V2,... with KEY a JSON pointer into "
                "the scene, e.g. /cloth/stretch=500,2000)"},
        BadFarm{"SweepStrayBracket", "optimize scene.json --sweep '/controls/alpha=]1,2'", kExitInput,
                "--sweep /controls/alpha=]1,2: a ] or } without its opening bracket (expected KEY=V1,V2,... with KEY a "
                "JSON pointer into the scene, e.g. /cloth/stretch=500,2000)"},
        BadFarm{"SweepValueWithNewline", "optimize scene.json --sweep \"$(printf '/controls/alpha=1\\n2')\"",
                kExitInput,
                "--sweep /controls/alpha=1\\n2: contains a control character (expected KEY=V1,V2,... with KEY a JSON "
                "pointer into the scene, e.g. /cloth/stretch=500,2000)"},
        BadFarm{"OutWithNewline", "optimize scene.json --sweep /controls/alpha=1,2 --dry-run "
                "--out \"$(printf 'nl\\ntouch PWNED\\n#')\"", kExitInput,
                "--out: contains a control character, got \"$DIR/nl\\ntouch PWNED\\n#\" (a job script cannot hold it)"},
        BadFarm{"KeyframeProgramWithNewline", "render run --dry-run --keyframe \"$(printf '/bin/k\\nrm -rf x')\"",
                kExitInput, "--keyframe: contains a control character, got \"/bin/k\\nrm -rf x\" (a job script cannot "
                "hold it)"},
        BadFarm{"SbatchOptionWithTab", "render run --sbatch=\"$(printf -- '--qos=a\\tb')\"", kExitInput,
                "--sbatch: expected one sbatch option such as --qos=high, got \"--qos=a\\tb\""}),
    [](const ::testing::TestParamInfo<BadFarm>& info) { return std::string(info.param.name); });

// A newline in a path that reaches a job script would end the `#` comment or `#SBATCH` line it is on and
// start a command of its own: such paths are refused before anything is written or submitted.
TEST_F(Farm, RunDirectoryWithANewlineIsRefusedNotWrittenIntoAScript) {
  const std::string evil = "nl\ntouch PWNED\n#";
  fs::copy(dir_ / "run", dir_ / evil, fs::copy_options::recursive);
  const auto before = list_tree(dir_);
  for (const char* extra : {" --dry-run", ""}) {
    const CliResult r = farm(std::string("render \"$(printf 'nl\\ntouch PWNED\\n#')\"") + extra);
    EXPECT_EQ(r.code, kExitInput) << r.output;
    EXPECT_EQ(r.output, "keyframe: error: RUN_DIR: contains a control character, got \"" + dir_.string() +
                            "/nl\\ntouch PWNED\\n#\" (a job script cannot hold it)\n");
  }
  EXPECT_TRUE(sbatch_calls().empty());
  EXPECT_EQ(list_tree(dir_), before);
  EXPECT_FALSE(fs::exists(dir_ / "PWNED"));
}

TEST_F(Farm, SceneFileNameWithANewlineIsRefused) {
  // The scene's name sets the default --out, which the scripts name.
  write("nl\ntouch PWNED\n#.json", small_flock_scene(11));
  const auto before = list_tree(dir_);
  const CliResult r = farm("optimize \"$(printf 'nl\\ntouch PWNED\\n#.json')\" --sweep /controls/alpha=1,2");
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_EQ(count_lines(r.output), 1) << r.output;
  EXPECT_NE(r.output.find("contains a control character"), std::string::npos) << r.output;
  EXPECT_TRUE(sbatch_calls().empty());
  EXPECT_EQ(list_tree(dir_), before);
}

// What gather reads back is validated like a scene: wrong types are exit 3 naming the file and the key.
class FarmGather : public Farm {
 protected:
  void SetUp() override {
    Farm::SetUp();
    ASSERT_EQ(farm("optimize scene.json --sweep /controls/alpha=0.01,0.1 --out sweep").code, 0);
    for (int task = 0; task < 2; ++task) ASSERT_EQ(run_script(dir_ / "sweep/farm/optimize.sbatch", task).code, 0);
    ASSERT_EQ(run_keyframe("farm gather sweep", dir_).code, 0);
  }
  void expect_gather_refused(const std::string& message) {
    const std::string csv = read_text(dir_ / "sweep/sweep.csv");
    const CliResult r = run_keyframe("farm gather sweep", dir_);
    EXPECT_EQ(r.code, kExitInput) << r.output;
    EXPECT_EQ(r.output, "keyframe: error: " + message + "\n");
    EXPECT_EQ(read_text(dir_ / "sweep/sweep.csv"), csv) << "gather rewrote sweep.csv from bad input";
  }
  // Replaces `from` by `to` in FILE (relative to the sweep directory).
  void edit(const std::string& file, const std::string& from, const std::string& to) {
    std::string text = read_text(dir_ / "sweep" / file);
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from << " not in " << file;
    write_text(dir_ / "sweep" / file, text.replace(at, from.size(), to));
  }
};

TEST_F(FarmGather, ReportWithAStringObjectiveIsRefused) {
  edit("scene_alpha=0.1/report.json", "\"final_objective\": ", "\"final_objective\": \"abc\", \"was\": ");
  expect_gather_refused("sweep/scene_alpha=0.1/report.json: /final_objective: expected a finite number, got "
                        "string \"abc\"");
}

TEST_F(FarmGather, ReportWithAStringInterruptedIsRefused) {
  edit("scene_alpha=0.01/report.json", "\"interrupted\": false", "\"interrupted\": \"no\"");
  expect_gather_refused("sweep/scene_alpha=0.01/report.json: /interrupted: expected true or false, got string \"no\"");
}

TEST_F(FarmGather, DeeplyNestedReportIsRefusedWithoutCrashing) {
  write_text(dir_ / "sweep/scene_alpha=0.1/report.json",
             R"({"x": )" + std::string(100000, '[') + std::string(100000, ']') + "}");
  expect_gather_refused("sweep/scene_alpha=0.1/report.json: line 1: JSON nested deeper than 256 levels");
}

// Submitting a sweep again reads each run's report.json to skip finished runs: the same checks, before
// anything is submitted or written.
TEST_F(FarmGather, ResubmittingOverAReportWithAStringInterruptedIsRefused) {
  edit("scene_alpha=0.01/report.json", "\"interrupted\": false", "\"interrupted\": \"no\"");
  const auto before = list_tree(dir_);
  const std::string script = read_text(dir_ / "sweep/farm/optimize.sbatch"), calls = sbatch_calls();
  const CliResult r = farm("optimize scene.json --sweep /controls/alpha=0.01,0.1 --out sweep");
  EXPECT_EQ(r.code, kExitInput) << r.output;
  EXPECT_EQ(r.output, "keyframe: error: " + (dir_ / "sweep/scene_alpha=0.01/report.json").string() +
                          ": /interrupted: expected true or false, got string \"no\"\n");
  EXPECT_EQ(sbatch_calls(), calls) << "submitted again";
  EXPECT_EQ(list_tree(dir_), before);
  EXPECT_EQ(read_text(dir_ / "sweep/farm/optimize.sbatch"), script);
}

TEST_F(FarmGather, ManifestWithOddKeysIsRefused) {
  edit("sweep.json", "\"keys\": [", "\"keys\": [7, ");
  expect_gather_refused("sweep/sweep.json: /keys/0: expected a JSON pointer such as \"/cloth/stretch\", got number 7");
}

TEST_F(FarmGather, ManifestRunNameThatLeavesTheSweepIsRefused) {
  edit("sweep.json", "\"name\": \"scene_alpha=0.01\"", "\"name\": \"../../elsewhere\"");
  expect_gather_refused("sweep/sweep.json: /runs/0/name: the run's directory name contains '/', got "
                        "\"../../elsewhere\"");
}

}  // namespace
}  // namespace kf::reliability
