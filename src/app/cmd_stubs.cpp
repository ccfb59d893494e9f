// Subcommands that are not available yet say so plainly.
#include "app/commands.h"

namespace kf {

static void add_not_ready(CLI::App& app, const char* name, const char* what) {
  auto* sub = app.add_subcommand(name, std::string(what) + " (not available yet)");
  sub->allow_extras();
  sub->callback([name] { throw NotReady(std::string("'") + name + "' is not available yet in this build"); });
}

void add_optimize_command(CLI::App& app) { add_not_ready(app, "optimize", "find the control forces that hit the keyframes"); }
void add_run_command(CLI::App& app) { add_not_ready(app, "run", "optimize, then render"); }
void add_render_command(CLI::App& app) { add_not_ready(app, "render", "render a run directory to PNG frames"); }
void add_gradcheck_command(CLI::App& app) { add_not_ready(app, "gradcheck", "compare the adjoint gradient with finite differences"); }
void add_figure_command(CLI::App& app) { add_not_ready(app, "figure", "compose figure sheets from run directories"); }
void add_bench_command(CLI::App& app) { add_not_ready(app, "bench", "sweep speed against error"); }

}  // namespace kf
