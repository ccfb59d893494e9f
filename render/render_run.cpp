#include "render/render_run.h"

#include <stdexcept>

namespace kf::render {

int render_run(const RenderRequest&) { throw std::runtime_error("rendering is not available yet"); }

}  // namespace kf::render
