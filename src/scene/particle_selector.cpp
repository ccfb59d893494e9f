#include "scene/particle_selector.h"

#include <algorithm>
#include <cstdio>

#include "scene/params.h"

namespace kf {

namespace {

std::vector<int> named_set(const std::string& name, int nx, int ny) {
  if (name == "all") return {};
  if (name != "edges") return named_pin_set(name, nx, ny);
  std::vector<int> out;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      if (i == 0 || j == 0 || i == nx - 1 || j == ny - 1) out.push_back(j * nx + i);
  return out;
}

std::string range_text(double a, double b) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%g … %g", a, b);
  return buf;
}

// The grid particles whose (i, j) and rest (u, v) pass every key of the selector object.
std::vector<int> object_set(Block s, const ClothSpec& c, const std::string& key, Block& parent) {
  int i0 = 0, i1 = c.nx - 1, j0 = 0, j1 = c.ny - 1;
  double u0 = -1e300, u1 = 1e300, v0 = -1e300, v1 = 1e300;
  bool any = false;
  auto narrow = [&](int& lo, int& hi, int a, int b) {
    lo = std::max(lo, std::min(a, b));
    hi = std::min(hi, std::max(a, b));
    any = true;
  };
  if (s.has("row")) {
    const int j = s.integer("row", 0, c.ny - 1);
    narrow(j0, j1, j, j);
  }
  if (s.has("column")) {
    const int i = s.integer("column", 0, c.nx - 1);
    narrow(i0, i1, i, i);
  }
  for (const char* k : {"i", "j"}) {
    if (!s.has(k)) continue;
    const bool along_i = k[0] == 'i';
    const std::vector<int> r = s.integers(k, 2, 0, (along_i ? c.nx : c.ny) - 1);
    if (r.size() != 2) s.fail(k, "expected two indices [first, last]");
    narrow(along_i ? i0 : j0, along_i ? i1 : j1, r[0], r[1]);
  }
  for (const char* k : {"u", "v"}) {
    if (!s.has(k)) continue;
    const std::vector<double> r = s.numbers(k, 2, -1e6, 1e6);
    if (r.size() != 2) s.fail(k, "expected two distances [from, to] in metres");
    (k[0] == 'u' ? u0 : v0) = std::min(r[0], r[1]);
    (k[0] == 'u' ? u1 : v1) = std::max(r[0], r[1]);
    any = true;
  }
  s.finish();
  if (!any) parent.fail(key, "expected a selector with at least one of \"row\", \"column\", \"i\", \"j\", \"u\", \"v\"");
  const double du = c.width / (c.nx - 1), dv = c.height / (c.ny - 1);
  std::vector<int> out;
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      const double u = i * du, v = j * dv;
      // Half a micrometre of slack: a region drawn to a row's exact distance includes it despite round-off.
      if (u >= u0 - 5e-7 && u <= u1 + 5e-7 && v >= v0 - 5e-7 && v <= v1 + 5e-7) out.push_back(c.index(i, j));
    }
  if (out.empty())
    parent.fail(key, "selects no particle of the " + std::to_string(c.nx) + " x " + std::to_string(c.ny) +
                         " sheet (" + s.json().dump() + "; i runs 0 … " + std::to_string(c.nx - 1) + ", j 0 … " +
                         std::to_string(c.ny - 1) + ", u " + range_text(0, c.width) + " m, v " +
                         range_text(0, c.height) + " m)");
  return out;
}

}  // namespace

const std::vector<std::string>& named_particle_sets() {
  static const std::vector<std::string> names = {"all",         "top_edge",    "bottom_edge",    "left_edge",
                                                 "right_edge",  "edges",       "corners",        "top_corners",
                                                 "bottom_corners"};
  return names;
}

std::vector<int> parse_particle_selector(Block& b, const std::string& key, int particles, const ClothSpec* sheet) {
  const Json& j = b.json().at(key);
  std::vector<int> out;
  if (sheet && sheet->mesh && !j.is_array()) {  // rows, columns and named edges are a grid's
    if (j.is_object()) b.fail(key, "expected vertex indices, \"all\" or a rest-space box {\"min\", \"max\"} (a mesh cloth)");
    b.string(key, std::vector<std::string>{"all"});
    for (int i = 0; i < particles; ++i) out.push_back(i);
  } else if (j.is_string()) {
    const std::string name =
        b.string(key, sheet ? named_particle_sets() : std::vector<std::string>{"all"});
    if (sheet) out = named_set(name, sheet->nx, sheet->ny);
  } else if (j.is_object() && sheet) {
    out = object_set(b.child(key), *sheet, key, b);
  } else if (j.is_object()) {
    b.fail(key, "expected particle indices or \"all\" (rows, columns and regions select a cloth's particles)");
  } else {
    out = b.integers(key, 1, 0, particles - 1);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

Vec3 rest_position(const ClothSpec& c, int index) {
  if (c.mesh) return c.mesh->vertices[size_t(index)];
  const int i = index % c.nx, j = index / c.nx;
  return c.origin + i * (c.width / (c.nx - 1)) * c.u_axis + j * (c.height / (c.ny - 1)) * c.v_axis;
}

}  // namespace kf
