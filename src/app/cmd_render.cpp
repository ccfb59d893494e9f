// keyframe render: render a run directory to PNG frames.
#include "app/commands.h"

namespace kf {

void add_render_command(CLI::App& app) {
  auto* sub = app.add_subcommand("render", "render a run directory to PNG frames (not available yet)");
  sub->allow_extras();
  sub->callback([] { throw NotReady("'render' is not available yet in this build"); });
}

}  // namespace kf
