// keyframe optimize: find the control forces that hit the keyframes.
#include "app/commands.h"

namespace kf {

void add_optimize_command(CLI::App& app) {
  auto* sub = app.add_subcommand("optimize", "find the control forces that hit the keyframes (not available yet)");
  sub->allow_extras();
  sub->callback([] { throw NotReady("'optimize' is not available yet in this build"); });
}

}  // namespace kf
