#pragma once
// keyframe clip: encode a run's rendered frames (RUN_DIR/frames/*.png) into an MP4 and/or GIF with ffmpeg.
#include <filesystem>
#include <string>
#include <vector>

namespace kf::render {

struct ClipRequest {
  std::filesystem::path run_dir;  // holds frames/frame_NNNN.png (from `keyframe render`)
  bool mp4 = true;                // RUN_DIR/clip.mp4: H.264, yuv420p, even size
  bool gif = false;               // RUN_DIR/clip.gif: palette per clip, at most 640 pixels wide
  bool turntable = false;         // encode frames/turntable_NNNN.png instead (turntable.mp4/.gif)
  double fps = 0.0;               // frames per second; 0: the trajectory's fps
  std::string ffmpeg = "ffmpeg";  // program name (looked up in PATH) or path
};

// The full path of `program` if it can be executed (a path, or a name found in PATH); empty otherwise.
std::filesystem::path find_program(const std::string& program);

// The ffmpeg argument lists (without the program) that encode `request`'s frames, one per output file;
// `inputs` is the printf pattern of the frames, `first` the first frame number, `outputs` the targets.
std::vector<std::vector<std::string>> clip_commands(const ClipRequest& request, const std::string& inputs, int first,
                                                    double fps, const std::vector<std::filesystem::path>& outputs);

// Throws InputError when there are no frames to encode (names the render command to run), OutputError
// when ffmpeg fails (outputs are written whole or not at all). The caller checks that ffmpeg exists.
// Returns the files written.
std::vector<std::filesystem::path> make_clip(const ClipRequest& request);

}  // namespace kf::render
