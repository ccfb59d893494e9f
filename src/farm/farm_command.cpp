// keyframe farm: render farms and optimisation sweeps as Slurm job arrays.
#include <unistd.h>

#include <iostream>

#include "app/cli_ranges.h"
#include "app/commands.h"
#include "farm/farm_render.h"
#include "farm/farm_sweep.h"
#include "app/run_dir.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "render/frame_renderer.h"

namespace kf {
namespace fs = std::filesystem;

namespace {

// Options every submitting farm command takes.
struct Submission {
  slurm::JobOptions slurm;
  bool dry_run = false;
  std::string keyframe;  // program the jobs run (default: this one)
};

void add_submission_options(CLI::App* sub, Submission& s) {
  sub->add_flag("--dry-run", s.dry_run, "print the scripts and the sbatch commands; write and submit nothing");
  sub->add_option("--partition", s.slurm.partition, "sbatch --partition for every job");
  sub->add_option("--account", s.slurm.account, "sbatch --account");
  sub->add_option("--time", s.slurm.time, "sbatch --time, the limit of each task (e.g. 2:00:00)");
  sub->add_option("--mem", s.slurm.mem, "sbatch --mem, memory per task (e.g. 8G)");
  sub->add_option("--constraint", s.slurm.constraint, "sbatch --constraint (node features)");
  sub->add_option("--sbatch", s.slurm.extra, "any further sbatch option, verbatim (repeatable): --sbatch=--qos=high")
      ->allow_extra_args(false);
  sub->add_option("--keyframe", s.keyframe,
                  "the keyframe program the jobs run (default: this one; it must be at that path on every node)");
}

fs::path keyframe_program(const Submission& s) {
  if (!s.keyframe.empty()) {
    slurm::check_script_text("--keyframe", s.keyframe);
    // On a shared filesystem the program the nodes run is visible here too (a dry run may name any path).
    if (!s.dry_run && access(s.keyframe.c_str(), X_OK) != 0)
      throw InputError("--keyframe " + s.keyframe + ": not an executable program");
    return fs::absolute(s.keyframe);
  }
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw InputError("cannot tell where keyframe itself is (" + ec.message() + "); pass --keyframe PATH");
  slurm::check_script_text("keyframe's own path", self.string());
  return self;
}

// Writes the scripts into `farm_dir` and submits the array, then the follow-up job after it.
void submit(const fs::path& farm_dir, const std::string& array_name, const std::string& array,
            const std::string& after_name, const std::string& after, const std::string& dependency) {
  const fs::path sbatch = slurm::require_sbatch();
  ensure_directory(farm_dir / "logs");
  write_file_atomic(farm_dir / array_name, array);
  write_file_atomic(farm_dir / after_name, after);
  const std::string id = slurm::submit(sbatch, {}, farm_dir / array_name);
  std::string then;
  try {
    then = slurm::submit(sbatch, {"--dependency=" + dependency + ":" + id}, farm_dir / after_name);
  } catch (...) {
    slurm::cancel(sbatch, id);  // no array without its follow-up job
    throw;
  }
  std::cout << "submitted job " << id << " (" << array_name << ") and job " << then << " (" << after_name
            << ", after " << id << "); logs in " << (farm_dir / "logs").string() << "\n";
}

void print_dry_run(const fs::path& farm_dir, const std::string& array_name, const std::string& array,
                   const std::string& after_name, const std::string& after, const std::string& dependency) {
  std::cout << "# " << (farm_dir / array_name).string() << "\n" << array << "\n";
  std::cout << "# " << (farm_dir / after_name).string() << "\n" << after << "\n";
  std::cout << "# submit with:\n# sbatch --parsable " << slurm::shell_quote((farm_dir / array_name).string())
            << "\n# sbatch --dependency=" << dependency << ":JOBID "
            << slurm::shell_quote((farm_dir / after_name).string()) << "\n";
}

void add_farm_render(CLI::App* farm) {
  auto* sub = farm->add_subcommand(
      "render", "render a run directory's frames as a Slurm job array (RUN_DIR/farm/render.sbatch), then check "
                "every frame and encode the clip in a dependent job (check.sbatch)");
  auto req = std::make_shared<render::RenderRequest>();
  auto opt = std::make_shared<Submission>();
  auto chunk = std::make_shared<int>(10);
  auto size = std::make_shared<std::string>();
  auto frames = std::make_shared<std::string>();
  sub->add_option("RUN_DIR", req->run_dir, "run directory holding scene.json and trajectory.bin")->required();
  sub->add_option("--frames", *frames, "frames A:B renders A..B-1 (default: all)");
  sub->add_option("--chunk", *chunk, "frames (or turntable views) per array task")->capture_default_str();
  sub->add_option("--backend", req->backend, "renderer: osmesa or embree")->capture_default_str();
  sub->add_option("--size", *size, "image size WxH in pixels (default: the scene's)");
  sub->add_option("--spp", req->spp, "samples per pixel (default: the back end's)");
  sub->add_option("--turntable", req->turntable, "render N views orbiting the first frame instead");
  add_submission_options(sub, *opt);
  sub->footer("Frames already complete (readable PNGs of the right size) are skipped, so submitting again\n"
              "renders only what is missing. Example:\n"
              "  keyframe farm render out/square --backend embree --size 1920x1080 --spp 64 --chunk 20 --time 1:00:00");
  sub->callback([=] {
    farm::RenderFarm f;
    f.request = *req;
    f.request.run_dir = fs::absolute(req->run_dir).lexically_normal();
    slurm::check_script_text("RUN_DIR", f.request.run_dir.string());  // before anything reads or writes it
    if (!size->empty()) parse_size(*size, f.request.width, f.request.height);
    if (!frames->empty()) parse_frames(*frames, f.request.frame_begin, f.request.frame_end);
    f.chunk = *chunk;
    f.slurm = opt->slurm;
    f.keyframe = keyframe_program(*opt);
    if (!opt->dry_run) slurm::require_sbatch();  // before any work: nothing to do without Slurm
    const farm::RenderPlan plan = farm::plan_render_farm(f);
    const std::string what = plan.turntable ? "turntable views" : "frames";
    if (plan.chunks.empty()) {
      std::cout << "all " << plan.last - plan.first << " " << what << " of " << f.request.run_dir.string()
                << " are complete; nothing to submit\n";
      return;
    }
    if (plan.complete > 0)
      std::cout << plan.complete << " of " << plan.last - plan.first << " " << what << " already complete (skipped)\n";
    if (opt->dry_run)
      print_dry_run(plan.farm_dir, "render.sbatch", plan.render_script, "check.sbatch", plan.check_script, "afterok");
    else
      submit(plan.farm_dir, "render.sbatch", plan.render_script, "check.sbatch", plan.check_script, "afterok");
  });
}

void add_farm_optimize(CLI::App* farm) {
  auto* sub = farm->add_subcommand(
      "optimize", "optimise scenes, or one scene over a grid of parameter values, as a Slurm job array (one "
                  "run directory each), then gather their report.json into sweep.csv and sweep.png");
  auto scenes = std::make_shared<std::vector<std::string>>();
  auto sweeps = std::make_shared<std::vector<std::string>>();
  auto out = std::make_shared<std::string>();
  auto max_evaluations = std::make_shared<int>(-1);
  auto opt = std::make_shared<Submission>();
  sub->add_option("SCENE", *scenes, "scene files (JSON)")->required();
  sub->add_option("--sweep", *sweeps,
                  "KEY=V1,V2,...: a JSON pointer into the scene and its values (repeatable: the grid of all)")
      ->allow_extra_args(false);
  sub->add_option("--out", *out, "sweep directory (default: out/sweep-<first scene>/)");
  sub->add_option("--max-evaluations", *max_evaluations, "passed to every keyframe optimize")
      ->check(CLI::Range(0, 1000000));
  add_submission_options(sub, *opt);
  sub->footer("Runs that finished (report.json, not interrupted) are skipped when submitting again. Example:\n"
              "  keyframe farm optimize scenes/arch.json --sweep /cloth/stretch=500,2000 --sweep /time/substeps=2,4");
  sub->callback([=] {
    std::vector<farm::Sweep> parsed;
    std::vector<fs::path> files(scenes->begin(), scenes->end());
    farm::SweepFarm f;
    for (const auto& s : *sweeps) {
      parsed.push_back(farm::parse_sweep(s));
      f.keys.push_back(parsed.back().key);
    }
    f.runs = farm::plan_sweep(files, parsed);
    f.out = fs::absolute(out->empty() ? fs::path("out") / ("sweep-" + f.runs.front().scene) : fs::path(*out))
                .lexically_normal();
    slurm::check_script_text(out->empty() ? "SCENE (its name names the sweep directory; or pass --out)" : "--out",
                             f.out.string());
    f.max_evaluations = *max_evaluations;
    f.slurm = opt->slurm;
    f.keyframe = keyframe_program(*opt);
    if (!opt->dry_run) slurm::require_sbatch();
    const farm::SweepPlan plan = farm::plan_sweep_farm(f);
    if (plan.todo.empty()) {
      std::cout << "all " << f.runs.size() << " runs in " << f.out.string() << " have finished; nothing to submit\n";
      return;
    }
    if (plan.todo.size() < f.runs.size())
      std::cout << f.runs.size() - plan.todo.size() << " of " << f.runs.size() << " runs already finished (skipped)\n";
    const fs::path farm_dir = f.out / "farm";
    if (opt->dry_run) {
      print_dry_run(farm_dir, "optimize.sbatch", plan.optimize_script, "gather.sbatch", plan.gather_script, "afterany");
      return;
    }
    // The point scenes and the manifest first: the jobs read them.
    ensure_directory(f.out / "scenes");
    for (size_t k : plan.todo) write_json(f.out / "scenes" / (f.runs[k].name + ".json"), f.runs[k].file);
    write_json(f.out / "sweep.json", farm::sweep_manifest(f));
    submit(farm_dir, "optimize.sbatch", plan.optimize_script, "gather.sbatch", plan.gather_script, "afterany");
  });
}

void add_farm_check(CLI::App* farm) {
  auto* sub = farm->add_subcommand("check", "check that a run's frames are complete PNGs (the render farm's last job)");
  auto dir = std::make_shared<std::string>();
  auto frames = std::make_shared<std::string>();
  auto size = std::make_shared<std::string>();
  auto turntable = std::make_shared<int>(0);
  sub->add_option("RUN_DIR", *dir, "run directory")->required();
  sub->add_option("--frames", *frames, "frames A:B (A..B-1; default: all)");
  sub->add_option("--turntable", *turntable, "check turntable views 0..N-1 instead")->check(CLI::Range(1, 100000));
  sub->add_option("--size", *size, "the frames' size WxH (default: any)");
  sub->callback([=] {
    int w = 0, h = 0, first = 0, last = -1;
    if (!size->empty()) parse_size(*size, w, h);
    if (!frames->empty()) parse_frames(*frames, first, last);
    if (*turntable > 0) {
      first = 0;
      last = *turntable;
    } else if (last < 0) {
      last = render::load_run(*dir).trajectory.frames();
    }
    const int n = farm::check_frames(*dir, first, last, *turntable > 0, w, h);
    std::cout << "all " << n << (*turntable > 0 ? " turntable views" : " frames") << " of " << *dir
              << " are complete PNGs\n";
  });
}

void add_farm_gather(CLI::App* farm) {
  auto* sub = farm->add_subcommand("gather", "gather a sweep's report.json files into sweep.csv and sweep.png "
                                             "(the optimisation farm's last job)");
  auto dir = std::make_shared<std::string>();
  sub->add_option("SWEEP_DIR", *dir, "sweep directory written by keyframe farm optimize")->required();
  sub->callback([=] {
    const auto unfinished = farm::gather_sweep(*dir);
    std::cout << "gathered -> " << (fs::path(*dir) / "sweep.csv").string() << "\n";
    if (!unfinished.empty()) {
      std::string names;
      for (const auto& n : unfinished) names += (names.empty() ? "" : ", ") + n;
      throw InputError(std::to_string(unfinished.size()) + " run" + (unfinished.size() == 1 ? "" : "s") +
                       " did not finish (" + names + "); sweep.csv marks them");
    }
  });
}

}  // namespace

void add_farm_command(CLI::App& app) {
  auto* farm = app.add_subcommand("farm", "run renders and optimisation sweeps on a Slurm cluster as job arrays");
  farm->require_subcommand(1);
  add_farm_render(farm);
  add_farm_optimize(farm);
  add_farm_check(farm);
  add_farm_gather(farm);
}

}  // namespace kf
