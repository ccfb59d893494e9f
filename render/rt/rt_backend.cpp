#include <stdexcept>

#include "render/backend.h"

namespace kf::render {
std::unique_ptr<Backend> make_rt_backend() { throw std::runtime_error("embree back end not built yet"); }
}  // namespace kf::render
