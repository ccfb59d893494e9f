#include "render/clip/make_clip.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <regex>
#include <set>

#include "core/error.h"
#include "render/image/png_io.h"

extern char** environ;

namespace kf::render {

namespace fs = std::filesystem;

namespace {

// Runs argv[0] with `args`, waiting for it; returns its exit status (127: could not start).
int run_program(const fs::path& program, const std::vector<std::string>& args) {
  std::vector<std::string> all{program.string()};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, program.c_str(), nullptr, nullptr, argv.data(), environ) != 0) return 127;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return 127;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// The trajectory's frame rate from the header of RUN_DIR/trajectory.bin (see core/trajectory.h).
double trajectory_fps(const fs::path& run_dir) {
  std::ifstream in(run_dir / "trajectory.bin", std::ios::binary);
  char header[24];
  double fps = 0.0;
  if (in.read(header, 24) && std::memcmp(header, "KFTRAJ01", 8) == 0) std::memcpy(&fps, header + 16, 8);
  return fps > 0.0 && fps < 1000.0 ? fps : 30.0;
}

}  // namespace

fs::path find_program(const std::string& program) {
  if (program.empty()) return {};
  if (program.find('/') != std::string::npos) return access(program.c_str(), X_OK) == 0 ? fs::path(program) : fs::path();
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "/usr/local/bin:/usr/bin:/bin";
  size_t start = 0;
  while (start <= dirs.size()) {
    const size_t end = std::min(dirs.find(':', start), dirs.size());
    const fs::path candidate = fs::path(dirs.substr(start, end - start).empty() ? "." : dirs.substr(start, end - start)) / program;
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec) && access(candidate.c_str(), X_OK) == 0) return candidate;
    start = end + 1;
  }
  return {};
}

std::vector<std::vector<std::string>> clip_commands(const ClipRequest& r, const std::string& inputs, int first,
                                                    double fps, const std::vector<fs::path>& outputs) {
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.6g", fps);
  const std::vector<std::string> input = {"-hide_banner", "-loglevel", "error", "-y", "-framerate", rate,
                                          "-start_number", std::to_string(first), "-i", inputs};
  std::vector<std::vector<std::string>> commands;
  size_t k = 0;
  if (r.mp4) {
    auto c = input;
    // H.264 in yuv420p needs even sides; pad by one pixel rather than scale.
    c.insert(c.end(), {"-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p", "-crf", "18",
                       "-movflags", "+faststart", "-f", "mp4", outputs.at(k++).string()});
    commands.push_back(c);
  }
  if (r.gif) {
    auto c = input;
    // One palette for the whole clip keeps colours stable from frame to frame.
    c.insert(c.end(), {"-vf",
                       "scale='min(640,iw)':-2:flags=lanczos,split[a][b];[a]palettegen=stats_mode=diff[p];"
                       "[b][p]paletteuse=dither=bayer:bayer_scale=3",
                       "-loop", "0", "-f", "gif", outputs.at(k++).string()});
    commands.push_back(c);
  }
  return commands;
}

namespace {

void check_clip_request(const ClipRequest& r) {
  if (!r.mp4 && !r.gif) throw InputError("clip: nothing to make (choose MP4 and/or --gif)");
  if (r.fps < 0.0 || r.fps > 1000.0) throw InputError("clip: --fps " + std::to_string(r.fps) + " out of range (0..1000)");
}

// The numbers of the frames STEM_NNNN.png in `frames`.
std::set<int> frame_numbers(const fs::path& frames, const std::string& stem) {
  std::set<int> numbers;
  const std::regex re(stem + R"(_(\d{4,})\.png)");
  std::error_code ec;
  if (fs::is_directory(frames))
    for (const auto& e : fs::directory_iterator(frames, ec)) {
      std::smatch m;
      const std::string name = e.path().filename().string();
      if (std::regex_match(name, m, re)) numbers.insert(std::stoi(m[1]));
    }
  return numbers;
}

// The last frame of the run that starts at the first; frames must run without gaps: ffmpeg's image
// reader stops at the first missing number.
int last_of_gapless_run(const fs::path& frames, const std::set<int>& numbers) {
  const int first = *numbers.begin();
  int last = first;
  while (numbers.count(last + 1)) ++last;
  if (last != *numbers.rbegin())
    throw InputError(frames.string() + ": frames " + std::to_string(first) + ".." + std::to_string(last) +
                     " are followed by a gap (frame " + std::to_string(last + 1) +
                     " is missing); re-render the frames without gaps");
  return last;
}

// ffmpeg skips a frame it cannot decode and still exits 0; every frame is read here first instead.
void check_frames_decode(const fs::path& frames, const std::string& stem, int first, int last) {
  int width = 0, height = 0;
  char name[64];
  for (int k = first; k <= last; ++k) {
    std::snprintf(name, sizeof name, "_%04d.png", k);
    const fs::path file = frames / (stem + name);
    const Image img = read_png(file);
    if (k == first) width = img.width, height = img.height;
    if (img.width != width || img.height != height)
      throw InputError(file.string() + ": " + std::to_string(img.width) + "x" + std::to_string(img.height) +
                       " pixels, but frame " + std::to_string(first) + " has " + std::to_string(width) + "x" +
                       std::to_string(height) + "; re-render the frames at one size");
  }
}

// Runs each command writing its `.partial` file; on a failure removes them all.
void run_encoders(const fs::path& ffmpeg, const std::vector<std::vector<std::string>>& commands,
                  const std::vector<fs::path>& targets, const std::vector<fs::path>& temps) {
  std::error_code ec;
  for (size_t k = 0; k < commands.size(); ++k) {
    const int status = run_program(ffmpeg, commands[k]);
    if (status != 0) {
      for (const auto& t : temps) fs::remove(t, ec);
      throw OutputError("clip: ffmpeg failed with status " + std::to_string(status) + " writing " + targets[k].string());
    }
  }
}

}  // namespace

std::vector<fs::path> make_clip(const ClipRequest& r) {
  check_clip_request(r);
  const fs::path frames = r.run_dir / "frames";
  const std::string stem = r.turntable ? "turntable" : "frame";
  const std::string render_hint = r.turntable ? "keyframe render " + r.run_dir.string() + " --turntable 120"
                                              : "keyframe render " + r.run_dir.string();
  if (!fs::is_directory(r.run_dir)) throw InputError(r.run_dir.string() + ": not a run directory (does not exist)");
  const std::set<int> numbers = frame_numbers(frames, stem);
  if (numbers.empty())
    throw InputError(frames.string() + ": no " + stem + "_NNNN.png frames to encode (run `" + render_hint + "` first)");
  const int first = *numbers.begin(), last = last_of_gapless_run(frames, numbers);
  check_frames_decode(frames, stem, first, last);
  const fs::path ffmpeg = find_program(r.ffmpeg);
  if (ffmpeg.empty()) throw OutputError("clip: cannot run \"" + r.ffmpeg + "\"");
  const double fps = r.fps > 0.0 ? r.fps : trajectory_fps(r.run_dir);
  std::vector<fs::path> targets, temps;
  if (r.mp4) targets.push_back(r.run_dir / (stem == "frame" ? "clip.mp4" : "turntable.mp4"));
  if (r.gif) targets.push_back(r.run_dir / (stem == "frame" ? "clip.gif" : "turntable.gif"));
  for (const auto& t : targets) temps.push_back(t.string() + ".partial");
  run_encoders(ffmpeg, clip_commands(r, (frames / (stem + "_%04d.png")).string(), first, fps, temps), targets, temps);
  std::error_code ec;
  for (size_t k = 0; k < targets.size(); ++k) {
    fs::rename(temps[k], targets[k], ec);
    if (ec) throw OutputError(targets[k].string() + ": cannot write (" + ec.message() + ")");
  }
  return targets;
}

}  // namespace kf::render
