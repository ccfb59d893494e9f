// keyframe figure: compose figure sheets from run directories.
#include "app/commands.h"

namespace kf {

void add_figure_command(CLI::App& app) {
  auto* sub = app.add_subcommand("figure", "compose figure sheets from run directories (not available yet)");
  sub->allow_extras();
  sub->callback([] { throw NotReady("'figure' is not available yet in this build"); });
}

}  // namespace kf
