#include "farm/farm_render.h"

#include <cstdio>

#include "core/error.h"
#include "render/frame_renderer.h"
#include "render/image/png_io.h"

namespace kf::farm {
namespace fs = std::filesystem;

namespace {

fs::path frame_path(const fs::path& run_dir, int k, bool turntable) {
  char name[64];
  std::snprintf(name, sizeof name, turntable ? "turntable_%04d.png" : "frame_%04d.png", k);
  return run_dir / "frames" / name;
}

std::string range_text(int first, int last) { return std::to_string(first) + ":" + std::to_string(last); }

}  // namespace

std::vector<Range> plan_chunks(const std::vector<int>& todo, int chunk) {
  std::vector<Range> chunks;
  for (int k : todo) {
    if (chunks.empty() || chunks.back().last != k || chunks.back().last - chunks.back().first >= chunk)
      chunks.push_back({k, k + 1});
    else
      chunks.back().last = k + 1;
  }
  return chunks;
}

FrameState frame_state(const fs::path& png, int width, int height) {
  std::error_code ec;
  if (!fs::is_regular_file(png, ec)) return FrameState::missing;
  try {
    const render::Image img = render::read_png(png);
    if (width > 0 && (img.width != width || img.height != height)) return FrameState::wrong_size;
  } catch (const InputError&) {
    return FrameState::not_png;
  }
  return FrameState::complete;
}

const char* describe(FrameState s) {
  switch (s) {
    case FrameState::complete: return "complete";
    case FrameState::missing: return "missing";
    case FrameState::not_png: return "not a readable PNG";
    case FrameState::wrong_size: return "of another size";
  }
  return "?";
}

namespace {

// Checks the request and the frame range against the run; gives the end of the range (one past the last frame).
int checked_frame_end(const RenderFarm& farm, const render::RunData& run) {
  const render::RenderRequest& r = farm.request;
  const int F = run.trajectory.frames();
  const int end = r.frame_end < 0 ? F : r.frame_end;
  if (r.frame_begin < 0 || r.frame_begin >= F || end <= r.frame_begin || end > F)
    throw InputError("--frames " + range_text(r.frame_begin, r.frame_end) + " out of range: " + r.run_dir.string() +
                     " has frames 0.." + std::to_string(F - 1) + " (A:B renders A..B-1)");
  return end;
}

// The range, size and chunks of frames still to render; gives how many frames are to render.
int plan_frames(const RenderFarm& farm, const render::RunData& run, int end, RenderPlan& plan) {
  const render::RenderRequest& r = farm.request;
  plan.name = slurm::job_name(r.run_dir.filename().string());
  plan.turntable = r.turntable > 0;
  plan.first = plan.turntable ? 0 : r.frame_begin;
  plan.last = plan.turntable ? r.turntable : end;
  plan.width = r.width > 0 ? r.width : run.scene.render.width;
  plan.height = r.height > 0 ? r.height : run.scene.render.height;
  plan.farm_dir = r.run_dir / "farm";
  std::vector<int> todo;
  for (int k = plan.first; k < plan.last; ++k)
    if (frame_state(frame_path(r.run_dir, k, plan.turntable), plan.width, plan.height) != FrameState::complete)
      todo.push_back(k);
  plan.complete = plan.last - plan.first - int(todo.size());
  plan.chunks = plan_chunks(todo, farm.chunk);
  return int(todo.size());
}

// Quoted paths and words both scripts use.
struct ScriptWords {
  std::string kf, dir, logs, what, size;
};

ScriptWords script_words(const RenderFarm& farm, const RenderPlan& plan) {
  const render::RenderRequest& r = farm.request;
  return {slurm::shell_quote(farm.keyframe.string()), slurm::shell_quote(r.run_dir.string()),
          slurm::shell_quote((plan.farm_dir / "logs").string()), plan.turntable ? "turntable views" : "frames",
          std::to_string(plan.width) + "x" + std::to_string(plan.height)};
}

// The array: task i renders chunks[i].
std::string render_script(const RenderFarm& farm, const RenderPlan& plan, const ScriptWords& w, std::size_t todo) {
  const render::RenderRequest& r = farm.request;
  std::string chunks;
  for (const auto& c : plan.chunks) {
    if (!chunks.empty()) chunks += ' ';
    chunks += range_text(c.first, c.last);
  }
  std::string s = "#!/bin/bash\n";
  s += "# keyframe farm render: " + w.what + " " + std::to_string(plan.first) + ".." + std::to_string(plan.last - 1) +
       " of " + r.run_dir.string() + ", " + std::to_string(todo) + " to render in " +
       std::to_string(plan.chunks.size()) + " tasks (" + r.backend + ", " + w.size + ")\n";
  s += "#SBATCH --job-name=keyframe-render-" + plan.name + "\n";
  s += "#SBATCH --array=0-" + std::to_string(int(plan.chunks.size()) - 1) + "\n";
  s += "#SBATCH --output=" + w.logs + "/render-%A_%a.out\n";
  s += slurm::sbatch_lines(farm.slurm);
  s += "set -euo pipefail\n";
  s += "keyframe=" + w.kf + "\nrun=" + w.dir + "\n";
  s += "chunks=(" + chunks + ")\n";
  s += "exec \"$keyframe\" --threads \"${SLURM_CPUS_PER_TASK:-0}\" render \"$run\"";
  if (plan.turntable)
    s += " --frames " + std::to_string(r.frame_begin) + " --turntable " + std::to_string(r.turntable) +
         " --views \"${chunks[$SLURM_ARRAY_TASK_ID]}\" \\\n  ";
  else
    s += " --frames \"${chunks[$SLURM_ARRAY_TASK_ID]}\" \\\n  ";
  s += "--backend " + slurm::shell_quote(r.backend) + " --size " + w.size;
  if (r.spp > 0) s += " --spp " + std::to_string(r.spp);
  s += "\n";
  return s;
}

// The check: runs once every task has succeeded (afterok on the command line).
std::string check_script(const RenderFarm& farm, const RenderPlan& plan, const ScriptWords& w) {
  const render::RenderRequest& r = farm.request;
  std::string s = "#!/bin/bash\n";
  s += "# keyframe farm render: check " + w.what + " " + std::to_string(plan.first) + ".." +
       std::to_string(plan.last - 1) + " of " + r.run_dir.string() + ", then encode the preview clip\n";
  s += "#SBATCH --job-name=keyframe-check-" + plan.name + "\n";
  s += "#SBATCH --output=" + w.logs + "/check-%j.out\n";
  s += "#SBATCH --kill-on-invalid-dep=yes\n";
  s += slurm::sbatch_lines(farm.slurm);
  s += "set -euo pipefail\n";
  s += "keyframe=" + w.kf + "\nrun=" + w.dir + "\n";
  s += "\"$keyframe\" farm check \"$run\"" +
       (plan.turntable ? " --turntable " + std::to_string(r.turntable)
                       : " --frames " + range_text(plan.first, plan.last)) +
       " --size " + w.size + "\n";
  s += "if command -v ffmpeg >/dev/null; then\n  \"$keyframe\" clip \"$run\"" +
       std::string(plan.turntable ? " --turntable" : "") + "\nelse\n  echo \"no ffmpeg on $(hostname): no clip\"\nfi\n";
  return s;
}

}  // namespace

RenderPlan plan_render_farm(const RenderFarm& farm) {
  const render::RenderRequest& r = farm.request;
  if (farm.chunk < 1)
    throw InputError("--chunk: expected at least 1 frame per task, got " + std::to_string(farm.chunk));
  render::check_request(r);
  slurm::check(farm.slurm);
  const render::RunData run = render::load_run(r.run_dir);
  const int end = checked_frame_end(farm, run);
  RenderPlan plan;
  const int todo = plan_frames(farm, run, end, plan);
  const ScriptWords words = script_words(farm, plan);
  plan.render_script = render_script(farm, plan, words, std::size_t(todo));
  plan.check_script = check_script(farm, plan, words);
  return plan;
}

int check_frames(const fs::path& run_dir, int first, int last, bool turntable, int width, int height) {
  std::string bad;
  int count = 0;
  for (int k = first; k < last; ++k) {
    const fs::path png = frame_path(run_dir, k, turntable);
    const FrameState s = frame_state(png, width, height);
    if (s == FrameState::complete) continue;
    if (++count <= 4) bad += (bad.empty() ? "" : ", ") + png.filename().string() + " " + describe(s);
  }
  if (count > 0)
    throw InputError((run_dir / "frames").string() + ": " + std::to_string(count) + " of " +
                     std::to_string(last - first) + (turntable ? " turntable views" : " frames") +
                     " not complete (" + bad + (count > 4 ? ", ..." : "") + ")");
  return last - first;
}

}  // namespace kf::farm
