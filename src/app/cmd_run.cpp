// keyframe run: optimize, then render.
#include "app/commands.h"

namespace kf {

void add_run_command(CLI::App& app) {
  auto* sub = app.add_subcommand("run", "optimize, then render (not available yet)");
  sub->allow_extras();
  sub->callback([] { throw NotReady("'run' is not available yet in this build"); });
}

}  // namespace kf
