#include "scene/cloth_spec.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "scene/cloth_mesh_spec.h"
#include "scene/params.h"
#include "scene/particle_selector.h"

namespace kf {

namespace {

const std::vector<std::string> kPinSets = {"none",        "top_edge",    "bottom_edge",    "left_edge",
                                           "right_edge",  "top_corners", "bottom_corners", "corners"};

Vec3 unit_vec3(Block& b, const std::string& key, const Vec3& def) {
  Vec3 a = b.vec3(key, def, -1e3, 1e3);
  if (a.norm() < 1e-9) b.fail(key, "expected a non-zero direction");
  return a.normalized();
}

// Each shape reads its own keys; the table below names the shapes the scene file may use.
ColliderShape parse_ground(Block& b) {
  GroundShape g;
  g.point = b.vec3("center", g.point);
  g.normal = unit_vec3(b, "axis", g.normal);
  return g;
}

ColliderShape parse_sphere(Block& b) {
  SphereShape s;
  s.center = b.vec3("center", s.center);
  s.radius = b.number("radius", s.radius, 1e-4, 1e4);
  return s;
}

ColliderShape parse_torus(Block& b) {
  TorusShape t;
  t.center = b.vec3("center", t.center);
  t.axis = unit_vec3(b, "axis", t.axis);
  t.radius = b.number("radius", t.radius, 1e-4, 1e4);
  t.tube_radius = b.number("tube_radius", t.tube_radius, 1e-5, 1e4);
  if (t.tube_radius >= t.radius) b.fail("tube_radius", "expected less than \"radius\" (a ring, not a spindle torus)");
  return t;
}

ColliderShape parse_capsule(Block& b) {
  CapsuleShape c;
  c.a = b.vec3("a", c.a);
  c.b = b.vec3("b", c.b);
  if ((c.b - c.a).norm() < 1e-6) b.fail("b", "expected a point away from \"a\" (the capsule's axis)");
  c.radius = b.number("radius", c.radius, 1e-4, 1e4);
  return c;
}

ColliderShape parse_box(Block& b) {
  BoxShape s;
  s.center = b.vec3("center", s.center);
  s.size = b.vec3("size", s.size, 1e-4, 1e4);
  s.u_axis = unit_vec3(b, "u_axis", s.u_axis);
  s.v_axis = unit_vec3(b, "v_axis", s.v_axis);
  if (std::abs(s.u_axis.dot(s.v_axis)) > 1e-6) b.fail("v_axis", "expected a direction perpendicular to \"u_axis\"");
  const double smallest = s.size.minCoeff();
  s.radius = b.number("radius", std::min(s.radius, 0.5 * smallest), 1e-4, 1e4);
  if (s.radius > 0.5 * smallest)
    b.fail("radius", "expected at most half the smallest of \"size\" (the rounding fits inside the box)");
  return s;
}

ColliderShape parse_rectangle(Block& b) {
  RectangleShape s;
  s.center = b.vec3("center", s.center);
  s.u_axis = unit_vec3(b, "u_axis", s.u_axis);
  s.v_axis = unit_vec3(b, "v_axis", -Vec3::UnitZ());  // facing +Y: a table top
  if (std::abs(s.u_axis.dot(s.v_axis)) > 1e-6) b.fail("v_axis", "expected a direction perpendicular to \"u_axis\"");
  s.width = b.number("width", s.width, 1e-4, 1e4);
  s.height = b.number("height", s.height, 1e-4, 1e4);
  return s;
}

struct ColliderType {
  const char* name;
  ColliderShape (*parse)(Block&);
};
const ColliderType kColliderTypes[] = {
    {GroundShape::kName, parse_ground},
    {SphereShape::kName, parse_sphere},
    {TorusShape::kName, parse_torus},
    {CapsuleShape::kName, parse_capsule},
    {BoxShape::kName, parse_box},
    {RectangleShape::kName, parse_rectangle},
};

ColliderSpec parse_collider(Block b) {
  std::vector<std::string> names;
  for (const ColliderType& t : kColliderTypes) names.push_back(t.name);
  const std::string type = b.string("type", names);
  ColliderSpec c;
  for (const ColliderType& t : kColliderTypes)
    if (type == t.name) c.shape = t.parse(b);
  c.thickness = b.number("thickness", c.thickness, 1e-6, 10.0);
  c.stiffness = b.number("stiffness", c.stiffness, 0.0, 1e9);
  c.friction = b.number("friction", c.friction, 0.0, 10.0);
  c.friction_velocity = b.number("friction_velocity", c.friction_velocity, 1e-6, 100.0);
  b.finish();
  return c;
}

}  // namespace

std::vector<int> named_pin_set(const std::string& name, int nx, int ny) {
  std::vector<int> out;
  auto idx = [nx](int i, int j) { return j * nx + i; };
  if (name == "none") {
  } else if (name == "top_edge") {
    for (int i = 0; i < nx; ++i) out.push_back(idx(i, ny - 1));
  } else if (name == "bottom_edge") {
    for (int i = 0; i < nx; ++i) out.push_back(idx(i, 0));
  } else if (name == "left_edge") {
    for (int j = 0; j < ny; ++j) out.push_back(idx(0, j));
  } else if (name == "right_edge") {
    for (int j = 0; j < ny; ++j) out.push_back(idx(nx - 1, j));
  } else if (name == "top_corners") {
    out = {idx(0, ny - 1), idx(nx - 1, ny - 1)};
  } else if (name == "bottom_corners") {
    out = {idx(0, 0), idx(nx - 1, 0)};
  } else if (name == "corners") {
    out = {idx(0, 0), idx(nx - 1, 0), idx(0, ny - 1), idx(nx - 1, ny - 1)};
  } else {
    throw std::invalid_argument("unknown pin set \"" + name + "\"");
  }
  std::sort(out.begin(), out.end());
  return out;
}

// The pinned particles: a rest-space box, a named group, a named edge set, a selector or indices.
static void parse_pins(Block& b, ClothSpec& s) {
  const int p = s.particles();
  if (b.has("pins") && is_rest_box(b.json().at("pins"))) {
    Block region = b.child("pins");
    s.pins = particles_in_region(region, s);
  } else if (b.has("pins") && is_group_set(b.json().at("pins"))) {
    Block group = b.child("pins");
    s.pins = particles_in_group(group, s);
  } else if (s.mesh && b.has("pins") && b.json().at("pins").is_string()) {
    s.pins = {};
    b.string("pins", "none", {"none"});  // the named edges are a grid's
  } else if (b.has("pins") && b.json().at("pins").is_string()) {
    s.pins = named_pin_set(b.string("pins", "none", kPinSets), s.nx, s.ny);
  } else if (b.has("pins") && b.json().at("pins").is_object()) {
    s.pins = parse_particle_selector(b, "pins", p, &s);  // a row, a column, a rectangle of (i, j), a region
  } else if (b.has("pins")) {
    s.pins = b.integers("pins", 0, 0, p - 1);
    std::sort(s.pins.begin(), s.pins.end());
    s.pins.erase(std::unique(s.pins.begin(), s.pins.end()), s.pins.end());
  }
}

// cloth.self: contact of the sheet with itself.
static void parse_self_contact(Block& b, ClothSpec& s) {
  s.self_stated = b.has("self");
  if (s.self_stated) {
    Block self = b.child("self");
    // Pairs closer than the particle spacing repel: farther apart, a layer's particles slip between another's.
    const double spacing = s.mesh ? s.self.thickness : std::min(s.width / (s.nx - 1), s.height / (s.ny - 1));
    s.self.enabled = self.boolean("enabled", true);
    s.self.thickness = self.number("thickness", spacing, 1e-5, 1.0);
    s.self.stiffness = self.number("stiffness", s.self.stiffness, 0.0, 1e8);
    s.self.friction = self.number("friction", s.self.friction, 0.0, 10.0);
    s.self.friction_velocity = self.number("friction_velocity", s.self.friction_velocity, 1e-6, 100.0);
    self.finish();
  }
}

ClothSpec parse_cloth_spec(Block& b, const std::filesystem::path& directory) {
  ClothSpec s;
  if (b.has("mesh")) {
    s.mesh = parse_cloth_mesh(b.child("mesh"), directory);
    s.mass_by_area = b.string("mass_by", "area", {"area", "uniform"}) == "area";
  } else {
    s.nx = b.integer("nx", s.nx, 2, 1024);
    s.ny = b.integer("ny", s.ny, 2, 1024);
    s.width = b.number("width", s.width, 1e-4, 1e4);
    s.height = b.number("height", s.height, 1e-4, 1e4);
    s.origin = b.vec3("origin", s.origin);
    s.u_axis = unit_vec3(b, "u_axis", s.u_axis);
    s.v_axis = unit_vec3(b, "v_axis", s.v_axis);
    if (std::abs(s.u_axis.dot(s.v_axis)) > 1e-6) b.fail("v_axis", "expected a direction perpendicular to \"u_axis\"");
  }
  s.mass = b.number("mass", s.mass, 1e-9, 1e6);
  parse_pins(b, s);
  s.stretch = b.number("stretch", s.stretch, 0.0, 1e9);
  s.shear = b.number("shear", s.shear, 0.0, 1e9);
  s.bend = b.number("bend", s.bend, 0.0, 1e9);
  s.buckle_strain = b.number("buckle_strain", s.buckle_strain, 1e-6, 1.0);
  s.buckle_stiffness = b.number("buckle_stiffness", s.buckle_stiffness, 0.0, 1.0);
  s.damping = b.number("damping", s.damping, 0.0, 1e6);
  s.air_drag = b.number("air_drag", s.air_drag, 0.0, 1e6);
  s.gravity = b.vec3("gravity", s.gravity, -1e4, 1e4);
  s.velocity = b.vec3("velocity", s.velocity, -1e4, 1e4);
  s.imperfection = b.number("imperfection", s.imperfection, 0.0, 0.01);
  s.imperfection_seed = b.integer("imperfection_seed", s.imperfection_seed, 0, 1'000'000'000);
  s.cg_tolerance_stated = b.has("cg_tolerance");
  s.cg_tolerance = b.number("cg_tolerance", s.cg_tolerance, 1e-16, 1e-1);
  s.cg_max_iterations = b.integer("cg_max_iterations", s.cg_max_iterations, 1, 1'000'000);
  s.cg_preconditioner = cg_preconditioner(
      b.string("cg_preconditioner", cg_preconditioner_name(s.cg_preconditioner), cg_preconditioner_names()));
  // PCG stays the default while optimising too: the direct solve's objective has no solver tolerance in it, but
  // it costs several times PCG's step and on the capes it reached fewer keyframes, not more
  // (tests/results/reachable/smooth/).
  s.solver = b.string("solver", s.solver, {"pcg", "direct"});
  s.control_integration = b.string("control_integration", s.control_integration, {"implicit", "explicit"});
  s.max_halvings = b.integer("max_halvings", s.max_halvings, 0, 16);
  s.contact_ramp = b.number("contact_ramp", s.contact_ramp, 0.0, 1.0);
  s.transverse_ramp = b.number("transverse_ramp", s.transverse_ramp, 1e-4, 1.0);
  s.theta = b.number("theta", s.theta, 0.5, 1.0);
  for (Block& c : b.array("colliders")) s.colliders.push_back(parse_collider(std::move(c)));
  parse_self_contact(b, s);
  b.finish();
  return s;
}

}  // namespace kf
