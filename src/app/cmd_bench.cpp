// keyframe bench: sweep speed against error.
#include "app/commands.h"

namespace kf {

void add_bench_command(CLI::App& app) {
  auto* sub = app.add_subcommand("bench", "sweep speed against error (not available yet)");
  sub->allow_extras();
  sub->callback([] { throw NotReady("'bench' is not available yet in this build"); });
}

}  // namespace kf
