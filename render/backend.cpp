#include "render/backend.h"

#include "core/error.h"

namespace kf::render {

namespace {
struct BackendEntry {
  const char* name;
  std::unique_ptr<Backend> (*make)();
};
constexpr BackendEntry kBackends[] = {
    {"osmesa", make_raster_backend},
    {"embree", make_rt_backend},
};
}  // namespace

std::vector<std::string> backend_names() {
  std::vector<std::string> names;
  for (const auto& e : kBackends) names.push_back(e.name);
  return names;
}

std::unique_ptr<Backend> make_backend(const std::string& name) {
  std::string choices;
  for (const auto& e : kBackends) {
    if (name == e.name) return e.make();
    choices += (choices.empty() ? "" : ", ") + std::string(e.name);
  }
  throw InputError("unknown render back end \"" + name + "\" (expected one of: " + choices + ")");
}

}  // namespace kf::render
