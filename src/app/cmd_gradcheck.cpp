// keyframe gradcheck: compare the adjoint gradient with finite differences.
#include "app/commands.h"

namespace kf {

void add_gradcheck_command(CLI::App& app) {
  auto* sub = app.add_subcommand("gradcheck", "compare the adjoint gradient with finite differences (not available yet)");
  sub->allow_extras();
  sub->callback([] { throw NotReady("'gradcheck' is not available yet in this build"); });
}

}  // namespace kf
