#include "render/backend.h"

#include "core/error.h"

namespace kf::render {

namespace {
// One row a back end: its name, its constructor and its samples per pixel when none are asked for.
struct BackendEntry {
  const char* name;
  std::unique_ptr<Backend> (*make)();
  int (*default_spp)(const RenderSpec& look);
};
constexpr BackendEntry kBackends[] = {
    {"osmesa", make_raster_backend, [](const RenderSpec&) { return 4; }},          // 4x MSAA
    {"embree", make_rt_backend, [](const RenderSpec& look) { return look.samples; }},  // render.samples
};

const BackendEntry& entry(const std::string& name) {
  std::string choices;
  for (const auto& e : kBackends) {
    if (name == e.name) return e;
    choices += (choices.empty() ? "" : ", ") + std::string(e.name);
  }
  throw InputError("unknown render back end \"" + name + "\" (expected one of: " + choices + ")");
}
}  // namespace

std::vector<std::string> backend_names() {
  std::vector<std::string> names;
  for (const auto& e : kBackends) names.push_back(e.name);
  return names;
}

std::unique_ptr<Backend> make_backend(const std::string& name) { return entry(name).make(); }

int default_spp(const std::string& name, const RenderSpec& look) { return entry(name).default_spp(look); }

}  // namespace kf::render
