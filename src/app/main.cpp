// keyframe: keyframe control of particle systems (flocks, cloth) with the adjoint method.
#include <cstdio>
#include <iostream>
#include <memory>
#include <tbb/global_control.h>

#include "app/commands.h"
#include "core/error.h"

int main(int argc, char** argv) {
  using namespace kf;
  CLI::App app{"keyframe: find the control forces that make a flock or a cloth hit its keyframes, then render it"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "keyframe 0.1");
  int threads = 0;
  app.add_option("--threads", threads, "worker threads (default: all cores); results do not depend on it")
      ->check(CLI::Range(0, 1024));
  std::unique_ptr<tbb::global_control> thread_limit;
  app.parse_complete_callback([&] {
    if (threads > 0)
      thread_limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  });
  add_simulate_command(app);
  add_optimize_command(app);
  add_run_command(app);
  add_render_command(app);
  add_gradcheck_command(app);
  add_figure_command(app);
  add_bench_command(app);
  add_clip_command(app);
  add_export_command(app);
  add_compare_command(app);
  add_farm_command(app);
  add_inspect_command(app);
  add_schema_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? kExitOk : kExitUsage;
  } catch (const InputError& e) {
    std::cerr << "keyframe: error: " << e.what() << "\n";
    return kExitInput;
  } catch (const OutputError& e) {
    std::cerr << "keyframe: error: " << e.what() << "\n";
    return kExitOutput;
  } catch (const FramesDiffer& e) {
    std::cerr << "keyframe: " << e.what() << "\n";
    return kExitDifferent;
  } catch (const NotReady& e) {
    std::cerr << "keyframe: " << e.what() << "\n";
    return kExitNotReady;
  } catch (const std::exception& e) {
    std::cerr << "keyframe: internal error: " << e.what() << "\n";
    return kExitInternal;
  }
  return kExitOk;
}
