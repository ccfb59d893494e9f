#include "render/camera_choice.h"

#include <array>
#include <cmath>
#include <sstream>

#include <Eigen/Geometry>

#include "core/error.h"

namespace kf::render {

namespace {

struct ViewRow {
  const char* name;
  NamedView view;
};
constexpr std::array<ViewRow, 4> kViews{{{"front", NamedView::kFront},
                                         {"side", NamedView::kSide},
                                         {"top", NamedView::kTop},
                                         {"three-quarter", NamedView::kThreeQuarter}}};

const char* kCameraForm = "expected eye=X,Y,Z target=X,Y,Z [fov=DEG] (metres, Y up; fov 1..170 degrees)";

[[noreturn]] void bad_camera(const std::string& text, const std::string& why) {
  throw InputError("--camera: " + why + " in \"" + text + "\"; " + kCameraForm);
}

// "X,Y,Z": three finite numbers.
Vec3 parse_point(const std::string& text, const std::string& key, const std::string& value) {
  Vec3 p;
  std::stringstream ss(value);
  for (int k = 0; k < 3; ++k) {
    std::string item;
    if (!std::getline(ss, item, ',')) bad_camera(text, key + " needs three numbers");
    try {
      size_t used = 0;
      p[k] = std::stod(item, &used);
      if (used != item.size() || !std::isfinite(p[k])) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      bad_camera(text, key + ": \"" + item + "\" is not a number");
    }
  }
  if (std::string rest; std::getline(ss, rest)) bad_camera(text, key + " needs three numbers");
  return p;
}

}  // namespace

std::string named_view_names() {
  std::string s;
  for (const auto& r : kViews) s += (s.empty() ? "" : "|") + std::string(r.name);
  return s;
}

NamedView parse_named_view(const std::string& text) {
  for (const auto& r : kViews)
    if (text == r.name) return r.view;
  throw InputError("--view: expected one of " + named_view_names() + ", got \"" + text + "\"");
}

CameraSpec parse_camera_option(const std::string& text) {
  CameraSpec c;
  c.fov = 0.0;
  bool eye = false, target = false;
  std::stringstream words(text);
  for (std::string w; words >> w;) {
    const size_t eq = w.find('=');
    const std::string key = w.substr(0, eq), value = eq == std::string::npos ? "" : w.substr(eq + 1);
    if (eq == std::string::npos) bad_camera(text, "\"" + w + "\" is not key=value");
    if (key == "eye") c.eye = parse_point(text, key, value), eye = true;
    else if (key == "target") c.target = parse_point(text, key, value), target = true;
    else if (key == "fov") {
      try {
        size_t used = 0;
        c.fov = std::stod(value, &used);
        if (used != value.size()) throw std::invalid_argument(value);
      } catch (const std::exception&) {
        bad_camera(text, "fov: \"" + value + "\" is not a number");
      }
      if (!(c.fov >= 1.0 && c.fov <= 170.0)) bad_camera(text, "fov " + value + " out of range");
    } else {
      bad_camera(text, "unknown key \"" + key + "\"");
    }
  }
  if (!eye || !target) bad_camera(text, eye ? "no target" : "no eye");
  const Vec3 d = c.target - c.eye;
  if (!(d.norm() > 1e-9)) bad_camera(text, "eye and target are the same point");
  c.up = d.normalized().cross(Vec3::UnitY()).norm() < 1e-6 ? Vec3(0, 0, -1) : Vec3::UnitY();
  return c;
}

CameraChoice parse_camera_choice(const std::string& camera, const std::string& view) {
  if (!camera.empty() && !view.empty())
    throw InputError("--camera and --view exclude each other: give one (got both)");
  CameraChoice c;
  if (!camera.empty()) c.camera = parse_camera_option(camera);
  if (!view.empty()) c.view = parse_named_view(view);
  return c;
}

Vec3 view_direction(NamedView view, Vec3& up) {
  up = Vec3::UnitY();
  switch (view) {
    case NamedView::kFront: return Vec3::UnitZ();
    case NamedView::kSide: return Vec3::UnitX();
    case NamedView::kTop: up = Vec3(0, 0, -1); return Vec3::UnitY();
    case NamedView::kThreeQuarter: break;
  }
  return Vec3(0.55, 0.42, 1.0).normalized();
}

}  // namespace kf::render
