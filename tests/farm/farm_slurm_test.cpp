// keyframe farm on a real Slurm: a one-node cluster on localhost renders a run in three array tasks and
// optimises a two-point sweep; the farm's frames must be bit for bit those of a local `keyframe render`.
#include <regex>

#include "local_slurm.h"
#include "render/clip/make_clip.h"

namespace kf::testing {
namespace {
using reliability::CliResult;
using reliability::read_text;
using reliability::write_text;

// Every job of the cluster has left the queue within `timeout_s` seconds.
bool wait_for_empty_queue(const LocalSlurm& slurm, int timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(timeout_s);
  while (std::chrono::steady_clock::now() < deadline) {
    const CliResult q = slurm.client("squeue -h -o '%i %j %T %r'", 10);
    if (q.code == 0 && q.output.empty()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  return false;
}

// "JobName=... JobState=..." of job `id` and, for an array, of each of its tasks: one line each.
std::vector<std::string> job_lines(const LocalSlurm& slurm, const std::string& id) {
  const CliResult r = slurm.client("scontrol -o show job " + id, 10);
  std::vector<std::string> lines;
  std::istringstream in(r.output);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(line);
  return lines;
}

// The ids in "submitted job A (...) and job B (...)".
std::pair<std::string, std::string> submitted_ids(const std::string& output) {
  std::smatch m;
  if (!std::regex_search(output, m, std::regex(R"(submitted job (\d+) .* and job (\d+) )"))) return {};
  return {m[1], m[2]};
}

class FarmSlurm : public reliability::TempDirTest {};

TEST_F(FarmSlurm, RenderInThreeChunksAndSweepOnALocalCluster) {
  const auto started = std::chrono::steady_clock::now();
  // A small run, and the frames a local render makes of it.
  write("scene.json", reliability::small_flock_scene(11));
  CliResult r = reliability::run_keyframe("simulate scene.json --out run", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  fs::copy(dir_ / "run", dir_ / "local", fs::copy_options::recursive);
  r = reliability::run_keyframe("render local --size 64x48", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  std::vector<fs::path> local;
  for (const auto& e : fs::directory_iterator(dir_ / "local" / "frames")) local.push_back(e.path());
  std::sort(local.begin(), local.end());
  ASSERT_GE(local.size(), 6u);
  const int frames = int(local.size());
  const int chunk = (frames + 2) / 3;

  std::unique_ptr<LocalSlurm> slurm;
  try {
    slurm = std::make_unique<LocalSlurm>();
  } catch (const std::exception& e) {
    FAIL() << e.what();
  }
  ASSERT_EQ(slurm->pids().size(), 3u);

  // The render farm: three array tasks, then the check job.
  // Through the shell with this cluster's SLURM_CONF, and a time limit in case sbatch hangs.
  r = LocalSlurm::shell("cd '" + dir_.string() + "' && " + slurm->env() + "timeout 60 '" KEYFRAME_BINARY
                        "' farm render run --size 64x48 --chunk " + std::to_string(chunk) + " --time 10:00");
  ASSERT_EQ(r.code, 0) << r.output;
  const auto [render_id, check_id] = submitted_ids(r.output);
  ASSERT_FALSE(render_id.empty()) << r.output;

  // The sweep: two optimisations of the scene at two control costs, then the gather job.
  r = LocalSlurm::shell("cd '" + dir_.string() + "' && " + slurm->env() + "timeout 60 '" KEYFRAME_BINARY
                        "' farm optimize scene.json --sweep /controls/alpha=0.01,0.1 --out sweep");
  ASSERT_EQ(r.code, 0) << r.output;
  const auto [optimize_id, gather_id] = submitted_ids(r.output);
  ASSERT_FALSE(optimize_id.empty()) << r.output;

  // Job names say what the jobs are while they are queued.
  const auto render_jobs = job_lines(*slurm, render_id);
  ASSERT_FALSE(render_jobs.empty());
  EXPECT_NE(render_jobs[0].find("JobName=keyframe-render-run "), std::string::npos) << render_jobs[0];

  ASSERT_TRUE(wait_for_empty_queue(*slurm, 150))
      << "jobs still queued after 150 s:\n" << slurm->client("squeue").output << "slurmd.log:\n"
      << slurm->log_tail("slurmd.log");

  // Every job and array task completed.
  const auto all_render = job_lines(*slurm, render_id);
  ASSERT_EQ(all_render.size(), 3u) << slurm->client("scontrol show job " + render_id).output;
  for (const std::string& id : {render_id, check_id, optimize_id, gather_id})
    for (const auto& line : job_lines(*slurm, id))
      EXPECT_NE(line.find("JobState=COMPLETED"), std::string::npos)
          << line << "\nlogs:\n" << LocalSlurm::shell("tail -n 5 '" + (dir_ / "run/farm/logs").string() + "'/* '" +
                                                      (dir_ / "sweep/farm/logs").string() + "'/*").output;
  for (const auto& line : job_lines(*slurm, check_id))
    EXPECT_NE(line.find("JobName=keyframe-check-run "), std::string::npos) << line;
  for (const auto& line : job_lines(*slurm, optimize_id))
    EXPECT_NE(line.find("JobName=keyframe-optimize-sweep "), std::string::npos) << line;

  // The farm's frames are the local frames, bit for bit.
  for (const auto& f : local) {
    const fs::path farm = dir_ / "run" / "frames" / f.filename();
    ASSERT_TRUE(fs::exists(farm)) << farm;
    EXPECT_EQ(read_text(farm), read_text(f)) << f.filename() << " differs";
  }
  EXPECT_EQ(fs::exists(dir_ / "run" / "clip.mp4"), !render::find_program("ffmpeg").empty());

  // The sweep: two run directories, one CSV row each with its alpha and a final objective.
  for (const char* run : {"scene_alpha=0.01", "scene_alpha=0.1"})
    EXPECT_TRUE(fs::exists(dir_ / "sweep" / run / "report.json")) << run;
  const std::string csv = read_text(dir_ / "sweep" / "sweep.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3) << csv;
  EXPECT_EQ(csv.rfind("run,scene,/controls/alpha,evaluations,wall_seconds,initial_objective,final_objective", 0), 0u)
      << csv;
  EXPECT_NE(csv.find("\nscene_alpha=0.01,scene,0.01,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\nscene_alpha=0.1,scene,0.1,"), std::string::npos) << csv;

  // Submitting again finds everything done and submits nothing.
  r = LocalSlurm::shell("cd '" + dir_.string() + "' && " + slurm->env() + "timeout 60 '" KEYFRAME_BINARY
                        "' farm render run --size 64x48 --chunk " + std::to_string(chunk));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("nothing to submit"), std::string::npos) << r.output;
  r = LocalSlurm::shell("cd '" + dir_.string() + "' && " + slurm->env() + "timeout 60 '" KEYFRAME_BINARY
                        "' farm optimize scene.json --sweep /controls/alpha=0.01,0.1 --out sweep");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("nothing to submit"), std::string::npos) << r.output;

  // Stopping the cluster ends exactly its three daemons.
  const std::vector<pid_t> pids = slurm->pids();
  slurm.reset();
  for (pid_t p : pids) EXPECT_NE(kill(p, 0), 0) << "daemon " << p << " still running";
  std::cout << "local Slurm test: " << std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count()
            << " s\n";
}

}  // namespace
}  // namespace kf::testing
