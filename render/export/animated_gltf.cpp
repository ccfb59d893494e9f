#include "render/export/animated_gltf.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstring>
#include <limits>

#include "core/atomic_file.h"
#include "core/error.h"

namespace kf::render {

namespace {

using json = nlohmann::json;

constexpr int kFloat = 5126, kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

// The buffer and the bufferView/accessor lists that point into it.
class BufferWriter {
 public:
  // A float accessor of `type` ("VEC3", "SCALAR") over `values`; `bounds` adds min/max (required for
  // positions and animation inputs).
  int floats(const std::vector<float>& values, const char* type, int components, bool bounds, int target = 0) {
    const int view = add_view(values.data(), values.size() * sizeof(float), target);
    json a = {{"bufferView", view}, {"componentType", kFloat}, {"count", values.size() / size_t(components)},
              {"type", type}};
    if (bounds) {
      std::vector<float> lo(size_t(components), std::numeric_limits<float>::max()), hi(size_t(components), -lo[0]);
      for (size_t i = 0; i < values.size(); ++i) {
        lo[i % size_t(components)] = std::min(lo[i % size_t(components)], values[i]);
        hi[i % size_t(components)] = std::max(hi[i % size_t(components)], values[i]);
      }
      a["min"] = lo;
      a["max"] = hi;
    }
    accessors_.push_back(std::move(a));
    return int(accessors_.size()) - 1;
  }
  int indices(const std::vector<uint32_t>& values) {
    const int view = add_view(values.data(), values.size() * sizeof(uint32_t), kElementArrayBuffer);
    accessors_.push_back(
        {{"bufferView", view}, {"componentType", kUnsignedInt}, {"count", values.size()}, {"type", "SCALAR"}});
    return int(accessors_.size()) - 1;
  }
  const std::string& bytes() const { return bytes_; }
  json views() const { return views_; }
  json accessors() const { return accessors_; }

 private:
  int add_view(const void* data, size_t size, int target) {
    json v = {{"buffer", 0}, {"byteOffset", bytes_.size()}, {"byteLength", size}};
    if (target) v["target"] = target;
    bytes_.append(static_cast<const char*>(data), size);  // every element is 4 bytes: offsets stay aligned
    views_.push_back(std::move(v));
    return int(views_.size()) - 1;
  }
  std::string bytes_;
  json views_ = json::array(), accessors_ = json::array();
};

std::vector<float> difference(const std::vector<float>& a, const std::vector<float>& b) {
  std::vector<float> d(a.size());
  for (size_t i = 0; i < a.size(); ++i) d[i] = a[i] - b[i];
  return d;
}

}  // namespace

void write_animated_gltf(const std::filesystem::path& gltf, const std::filesystem::path& bin,
                         const std::vector<MovingMesh>& objects, double fps) {
  BufferWriter buf;
  const size_t frames = objects.empty() ? 0 : objects.front().positions.size();
  // The animation: at frame k's time, target k has weight 1 and every other 0.
  std::vector<float> times(frames), weights(frames * frames, 0.0f);
  for (size_t k = 0; k < frames; ++k) times[k] = float(double(k) / fps), weights[k * frames + k] = 1.0f;
  json nodes = json::array(), meshes = json::array(), materials = json::array(), samplers = json::array(),
       channels = json::array();
  const int input = frames > 1 ? buf.floats(times, "SCALAR", 1, true) : -1;
  const int output = frames > 1 ? buf.floats(weights, "SCALAR", 1, false) : -1;
  for (size_t o = 0; o < objects.size(); ++o) {
    const MovingMesh& m = objects[o];
    // The rest shape is frame 0; target k moves it to frame k (target 0 moves nothing).
    json primitive = {{"attributes",
                       {{"POSITION", buf.floats(m.positions[0], "VEC3", 3, true, kArrayBuffer)},
                        {"NORMAL", buf.floats(m.normals[0], "VEC3", 3, false, kArrayBuffer)}}},
                      {"indices", buf.indices(m.indices)},
                      {"material", o},
                      {"mode", 4}};
    json targets = json::array();
    if (frames > 1)
      for (size_t k = 0; k < frames; ++k)
        targets.push_back(
            {{"POSITION", buf.floats(difference(m.positions[k], m.positions[0]), "VEC3", 3, true, kArrayBuffer)},
             {"NORMAL", buf.floats(difference(m.normals[k], m.normals[0]), "VEC3", 3, false, kArrayBuffer)}});
    json mesh = {{"name", m.name}};
    if (frames > 1) {
      primitive["targets"] = targets;
      std::vector<float> rest(frames, 0.0f);
      rest[0] = 1.0f;
      mesh["weights"] = rest;
      samplers.push_back({{"input", input}, {"output", output}, {"interpolation", "LINEAR"}});
      channels.push_back({{"sampler", samplers.size() - 1}, {"target", {{"node", o}, {"path", "weights"}}}});
    }
    mesh["primitives"] = json::array({primitive});
    meshes.push_back(std::move(mesh));
    nodes.push_back({{"name", m.name}, {"mesh", o}});
    materials.push_back({{"name", m.name},
                         {"doubleSided", true},
                         {"pbrMetallicRoughness",
                          {{"baseColorFactor", {m.color.x(), m.color.y(), m.color.z(), 1.0}},
                           {"metallicFactor", 0.0},
                           {"roughnessFactor", 0.8}}}});
  }
  json scene_nodes = json::array();
  for (size_t o = 0; o < objects.size(); ++o) scene_nodes.push_back(o);
  json doc = {{"asset", {{"version", "2.0"}, {"generator", "keyframe"}}},
              {"scene", 0},
              {"scenes", {{{"name", "keyframe"}, {"nodes", scene_nodes}}}},
              {"nodes", nodes},
              {"meshes", meshes},
              {"materials", materials},
              {"buffers", {{{"uri", bin.filename().string()}, {"byteLength", buf.bytes().size()}}}},
              {"bufferViews", buf.views()},
              {"accessors", buf.accessors()}};
  if (!channels.empty()) doc["animations"] = {{{"name", "keyframe"}, {"samplers", samplers}, {"channels", channels}}};
  write_file_atomic(bin, buf.bytes());
  write_file_atomic(gltf, doc.dump(1));
}

}  // namespace kf::render
