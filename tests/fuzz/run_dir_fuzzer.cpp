// libFuzzer target for the files keyframe reads back from a run directory and a sweep directory: the first
// byte picks the file (trajectory.bin, controls.bin, scene_name.txt, report.json, sweep.json,
// evaluations.bin, schedule.bin), the rest is its contents. Every input either reads or raises InputError; a crash, a hang or another exception is a
// finding.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/trajectory.h"
#include "farm/run_report.h"
#include "opt/controls_file.h"
#include "opt/evaluation_tape.h"
#include "opt/schedule_file.h"
#include "scene/run_name.h"

namespace {
namespace fs = std::filesystem;

const fs::path& scratch() {
  static const fs::path dir = [] {
    fs::path d = fs::temp_directory_path() / ("keyframe_run_dir_fuzz_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

void write_file(const fs::path& p, const uint8_t* data, size_t size) {
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), std::streamsize(size));
}

// A cloth scene whose runs hold their split pattern: what a schedule.bin is read against.
const kf::Scene& cloth_scene() {
  static const kf::Scene scene = [] {
    kf::Scene s;
    s.cloth = kf::ClothSpec{};
    return s;
  }();
  return scene;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const int which = data[0] % 7;
  const fs::path& dir = scratch();
  try {
    switch (which) {
      case 0:
        write_file(dir / "trajectory.bin", data + 1, size - 1);
        (void)kf::load_trajectory(dir / "trajectory.bin");
        break;
      case 1:
        write_file(dir / "controls.bin", data + 1, size - 1);
        (void)kf::load_controls(dir / "controls.bin");
        break;
      case 2:
        write_file(dir / "scene_name.txt", data + 1, size - 1);
        (void)kf::read_run_name(dir);
        break;
      case 3:
        write_file(dir / "report.json", data + 1, size - 1);
        (void)kf::farm::read_run_report(dir);
        break;
      case 4:
        write_file(dir / "sweep.json", data + 1, size - 1);
        (void)kf::farm::read_sweep_manifest(dir);
        break;
      case 5:
        write_file(dir / "schedule.bin", data + 1, size - 1);
        (void)kf::load_schedule(dir / "schedule.bin", cloth_scene(), kf::VecX::Zero(4), cloth_scene().time.substeps);
        break;
      default:
        write_file(dir / "evaluations.bin", data + 1, size - 1);
        (void)kf::load_evaluations(dir / "evaluations.bin");
        break;
    }
  } catch (const kf::InputError&) {
    // The expected outcome for malformed input.
  }
  return 0;
}
