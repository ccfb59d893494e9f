#pragma once
// keyframe farm render: a run directory's frames as a Slurm job array of `keyframe render --frames` tasks,
// then one dependent job that checks every frame and encodes the preview clip.
#include <filesystem>
#include <string>
#include <vector>

#include "farm/slurm.h"
#include "render/render_run.h"

namespace kf::farm {

// Frames (or turntable views) first..last-1.
struct Range {
  int first = 0, last = 0;
};

// Splits `todo` (increasing frame numbers) into runs of consecutive frames of at most `chunk` frames each.
std::vector<Range> plan_chunks(const std::vector<int>& todo, int chunk);

enum class FrameState { complete, missing, not_png, wrong_size };
// A frame is complete when it decodes as a PNG of width x height pixels (0 x 0: any size).
FrameState frame_state(const std::filesystem::path& png, int width, int height);
const char* describe(FrameState state);

struct RenderFarm {
  render::RenderRequest request;     // run_dir absolute; frames, backend, size, spp, turntable as given
  int chunk = 10;                    // frames (or turntable views) per array task, >= 1
  slurm::JobOptions slurm;           // the user's partition, account, limits
  std::filesystem::path keyframe;    // the keyframe program the jobs run (same path on every node)
};

struct RenderPlan {
  std::string name;                  // the run directory's name, for job names
  int first = 0, last = 0;           // frames (views) the request covers
  bool turntable = false;
  int width = 0, height = 0;         // the frames' size
  int complete = 0;                  // of them, already complete (skipped)
  std::vector<Range> chunks;         // one array task each; empty: nothing to render
  std::filesystem::path farm_dir;    // RUN_DIR/farm: the scripts and logs/
  std::string render_script, check_script;
};

// Validates the request and the run directory (throws InputError, reads only), finds the frames still to
// render and writes the two scripts' text.
RenderPlan plan_render_farm(const RenderFarm& farm);

// Checks frames first..last-1 (turntable views with `turntable`) of `run_dir` at width x height (0: any).
// Returns how many were checked; throws InputError naming the incomplete ones.
int check_frames(const std::filesystem::path& run_dir, int first, int last, bool turntable, int width, int height);

}  // namespace kf::farm
