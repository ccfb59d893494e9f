// The generator of reachable-by-construction scenes (bench_reachable.h): the base scenes of each class,
// their variants and the keyframes taken from the variant's motion.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "bench/bench_reachable.h"
#include "adjoint/rollout.h"
#include "opt/keyframes/keyframe_common.h"
#include "sim/make_system.h"

namespace kf {

namespace {

// splitmix64: the same numbers on every platform (std's distributions are not).
class Draw {
 public:
  explicit Draw(std::uint64_t seed) : s_(seed) {}
  double uniform(double lo, double hi) { return lo + (hi - lo) * double(next() >> 11) * 0x1.0p-53; }
  int integer(int lo, int hi) { return lo + int(next() % std::uint64_t(hi - lo + 1)); }  // lo..hi
  bool chance(double p) { return uniform(0, 1) < p; }
  Vec3 direction() {
    for (;;) {
      const Vec3 d(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
      if (d.norm() > 0.1 && d.norm() <= 1) return d.normalized();
    }
  }

 private:
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  std::uint64_t s_;
};

nlohmann::json vec(const Vec3& v) { return {v.x(), v.y(), v.z()}; }
Vec3 at(const VecX& x, int i) { return x.segment<3>(3 * i); }

struct ClassShare {
  const char* name;
  int share;  // scenes of 100; 0: outside the suite, drawn only when named (then `count` of them)
};
// Throws 22 %, characters 12 %; friction comes on drop, ground and throw scenes by their index. The poncho (a
// mesh with a neck hole on BCN_Epileptic.X, scenes/robustness/poncho.json's sheet) came after the suite was
// measured, so it stays out of the 100 and leaves every other scene as drawn.
constexpr ClassShare kClasses[] = {{"hang-corners", 9}, {"hang-edge", 9},   {"hang-points", 8},
                                   {"drop-collider", 12}, {"drop-ground", 10}, {"throw", 22},
                                   {"cape", 7},          {"cape-wuson", 5},  {"flock-position", 9},
                                   {"flock-shape", 9},   {"poncho", 0}};

// A collider of a random kind below a sheet centred at `c` (the sheet's height above it at c.y).
nlohmann::json random_collider(Draw& d, const Vec3& c, double size) {
  const Vec3 off(d.uniform(-0.3, 0.3) * size, 0, d.uniform(-0.3, 0.3) * size);
  switch (d.integer(0, 2)) {
    case 0:
      return {{"type", "sphere"}, {"center", vec(c + off - Vec3(0, 0.25 * size + 0.1, 0))}, {"radius", 0.2 * size}};
    case 1: {
      const double a = d.uniform(0, M_PI);
      const Vec3 axis(std::cos(a), 0, std::sin(a));
      const Vec3 mid = c + off - Vec3(0, 0.15, 0);
      return {{"type", "capsule"}, {"a", vec(mid - 0.4 * size * axis)}, {"b", vec(mid + 0.4 * size * axis)},
              {"radius", d.uniform(0.03, 0.1)}};
    }
    default:
      return {{"type", "torus"}, {"center", vec(c + off - Vec3(0, 0.15, 0))}, {"axis", {0, 1, 0}},
              {"radius", 0.3 * size}, {"tube_radius", 0.04}};
  }
}

// Two to four distinct particles of an n x n sheet, sorted.
std::vector<int> random_pins(Draw& d, int n) {
  std::vector<int> pins;
  const int count = d.integer(2, 4);
  while (int(pins.size()) < count) {
    const int p = d.integer(0, n * n - 1);
    if (std::find(pins.begin(), pins.end(), p) == pins.end()) pins.push_back(p);
  }
  std::sort(pins.begin(), pins.end());
  return pins;
}

// The sheet of a cloth class (its pins, colliders, start and controls).
nlohmann::json cloth_block(const std::string& kind, Draw& d, int index, bool reduced, ReachableScene& r) {
  const int n = reduced ? 8 : 8 + int(24 * std::pow(d.uniform(0, 1), 2));
  const double size = d.uniform(0.4, 1.4);
  nlohmann::json c = {{"nx", n}, {"ny", n}, {"width", size}, {"height", size}, {"mass", d.uniform(0.1, 0.6)}};
  nlohmann::json colliders = nlohmann::json::array();
  const double y = d.uniform(0.6, 1.2);
  const Vec3 centre(d.uniform(-0.5, 0.5), y, d.uniform(-0.5, 0.5));
  auto horizontal = [&] {
    c["origin"] = vec(centre - Vec3(size / 2, 0, size / 2));
    c["u_axis"] = {1, 0, 0};
    c["v_axis"] = {0, 0, 1};
  };
  auto vertical = [&] {  // hanging in a vertical plane turned by a random angle about y
    const double a = d.uniform(0, M_PI);
    const Vec3 u(std::cos(a), 0, std::sin(a));
    c["origin"] = vec(centre + Vec3(0, 0.6, 0) - size / 2 * u - Vec3(0, size, 0));
    c["u_axis"] = vec(u);
    c["v_axis"] = {0, 1, 0};
  };
  if (kind == "hang-corners") {
    vertical();
    c["pins"] = "top_corners";
  } else if (kind == "hang-edge") {
    vertical();
    c["pins"] = "top_edge";
  } else if (kind == "hang-points") {
    horizontal();
    c["pins"] = random_pins(d, n);
  } else if (kind == "drop-collider") {
    horizontal();
    colliders.push_back(random_collider(d, centre, size));
    colliders.push_back({{"type", "ground"}});
    r.friction = index % 2 == 1;
  } else if (kind == "drop-ground") {
    c["origin"] = vec(Vec3(centre.x(), d.uniform(0.05, 0.4), centre.z()) - Vec3(size / 2, 0, size / 2));
    c["u_axis"] = {1, 0, 0};
    c["v_axis"] = {0, 0, 1};
    colliders.push_back({{"type", "ground"}});
    r.friction = index % 4 != 0;
  } else if (kind == "throw") {
    horizontal();
    r.thrown = true;
    // Thrown up and sideways, or dropped (every third); over a collider half the time.
    const Vec3 v = index % 3 == 2 ? Vec3::Zero() : Vec3(d.uniform(-2, 2), d.uniform(1, 3), d.uniform(-2, 2));
    c["velocity"] = vec(v);
    if (index % 2 == 0) colliders.push_back(random_collider(d, centre + 0.3 * Vec3(v.x(), 0, v.z()), size));
    colliders.push_back({{"type", "ground"}});
    r.friction = index % 2 == 1;
  } else {
    throw std::invalid_argument("no cloth class " + kind);
  }
  if (r.friction)
    for (auto& col : colliders) col["friction"] = d.uniform(0.2, 0.6);
  if (!colliders.empty()) c["colliders"] = colliders;
  return c;
}

// A sheet on a character: a cape on one of the two (the robustness suite's settings, its size drawn), or the
// poncho.
void sheet_on_character(const std::string& kind, Draw& d, bool reduced, const std::filesystem::path& directory,
                        nlohmann::json& s) {
  const std::filesystem::path repo = KEYFRAME_REPOSITORY;
  const auto relative = [&](const char* asset) { return std::filesystem::proximate(repo / asset, directory).string(); };
  if (kind == "poncho") {  // scenes/robustness/poncho.json's sheet and pins, its mass drawn
    const int frames = reduced ? 15 : 30;
    s["time"] = {{"fps", 30}, {"substeps", 2}, {"frames", frames}};
    s["cloth"] = {{"mesh", {{"file", relative("assets/cloth/poncho.obj")}, {"offset", {0, 0.56, -0.15}}}},
                  {"mass", d.uniform(0.2, 0.4)},
                  {"pins", {{"min", {-0.16, 0.5, -0.31}}, {"max", {0.16, 0.6, 0.01}}}}};
    s["character"] = {{"file", relative("assets/character/BCN_Epileptic.X")},
                      {"time", {{0, 0.0}, {frames, frames / 30.0}}}};
  } else if (kind == "cape") {
    const int nx = reduced ? 8 : d.integer(8, 16), ny = reduced ? 12 : d.integer(14, 26);
    const double w = d.uniform(0.35, 0.5), h = d.uniform(0.6, 0.95);
    s["time"] = {{"fps", 30}, {"substeps", 2}, {"frames", reduced ? 15 : 30}};
    s["cloth"] = {{"nx", nx}, {"ny", ny}, {"width", w}, {"height", h}, {"mass", d.uniform(0.2, 0.4)},
                  {"origin", {-w / 2, 0.47 - h, -0.3}}};  // the top edge at the shoulder anchors
    s["character"] = {{"file", relative("assets/character/BCN_Epileptic.X")},
                      {"time", {{0, 0.0}, {reduced ? 15 : 30, reduced ? 0.5 : 1.0}}}};
  } else {
    const int nx = reduced ? 8 : d.integer(8, 14), ny = reduced ? 10 : d.integer(12, 20);
    const int frames = reduced ? 15 : 45;
    s["time"] = {{"fps", 30}, {"substeps", 2}, {"frames", frames}};
    s["cloth"] = {{"nx", nx},   {"ny", ny},   {"width", 0.7}, {"height", 1.0}, {"mass", d.uniform(0.2, 0.4)},
                  {"origin", {-0.35, 1.6, 0.4}}, {"u_axis", {1, 0, 0}}, {"v_axis", {0, 0, -1}}};
    s["character"] = {{"file", "/usr/share/assimp/models/X/Testwuson.X"},
                      {"animation", 1},
                      {"time", {{0, 0.0}, {frames, frames / 30.0}}},
                      // The body's vertices the robustness suite's cape-wuson hangs from (its anchors snap to them).
                      {"anchors",
                       {{"mesh", ""},
                        {"points",
                         {{-0.207355785, 1.31154378, -0.519524144},
                          {0, 1.34548016, -0.677886024},
                          {0.21213725, 1.29530657, -0.498971043}}}}}};
  }
}

// Keyframe frames: k of them spread over 1..frames, the last at the end.
std::vector<int> keyframe_frames(Draw& d, int k, int frames) {
  std::vector<int> f;
  for (int j = 1; j <= k; ++j) {
    const double jitter = j == k ? 0 : d.uniform(-0.08, 0.08);
    f.push_back(std::clamp(int(std::lround(frames * (double(j) / k + jitter))), 4, frames));
  }
  for (std::size_t j = 1; j < f.size(); ++j) f[j] = std::max(f[j], f[j - 1] + 2);
  for (int& x : f) x = std::min(x, frames);
  f.erase(std::unique(f.begin(), f.end()), f.end());
  return f;
}

// A mesh sheet's side: the particles within 8 % of its rest extent of its bound along x or z, either way.
std::vector<int> mesh_side(Draw& d, const VecX& rest) {
  const int axis = d.chance(0.5) ? 0 : 2;
  const bool high = d.chance(0.5);
  const Eigen::Map<const Eigen::Matrix3Xd> x(rest.data(), 3, rest.size() / 3);
  const double lo = x.row(axis).minCoeff(), hi = x.row(axis).maxCoeff(), band = 0.08 * (hi - lo);
  std::vector<int> p;
  for (int i = 0; i < int(x.cols()); ++i)
    if (high ? x(axis, i) >= hi - band : x(axis, i) <= lo + band) p.push_back(i);
  return p;
}

// The particles a cloth keyframe names: all, an edge (a mesh's side), a corner (a mesh's vertex), or a few.
std::vector<int> keyframe_particles(Draw& d, const ClothSpec& cl, const VecX& rest, int what) {
  const int nx = cl.nx, ny = cl.ny, count = cl.particles();
  const std::vector<int>& pins = cl.pins;
  std::vector<int> p;
  switch (what) {
    case 0: break;  // all
    case 1: {       // an edge away from the pins when there are any; a mesh's side (its pins left out below)
      if (cl.mesh) {
        p = mesh_side(d, rest);
        break;
      }
      const int j = pins.empty() || pins.front() >= nx ? 0 : ny - 1;
      const bool bottom_pinned = !pins.empty() && pins.front() < nx;
      for (int i = 0; i < nx; ++i) p.push_back((bottom_pinned ? 0 : j) * nx + i);
      if (bottom_pinned) for (int& x : p) x += (ny - 1) * nx;
      break;
    }
    case 2: p.push_back(cl.mesh ? d.integer(0, count - 1) : d.chance(0.5) ? 0 : nx - 1); break;  // a bottom corner
    default:
      while (int(p.size()) < 3) {
        const int i = d.integer(0, count - 1);
        if (std::find(p.begin(), p.end(), i) == p.end()) p.push_back(i);
      }
      std::sort(p.begin(), p.end());
  }
  std::vector<int> free;
  for (int i : p)
    if (!std::binary_search(pins.begin(), pins.end(), i)) free.push_back(i);
  return free.empty() && !p.empty() ? std::vector<int>{} : free;
}

// 2-D convex hull (monotone chain), counter-clockwise.
std::vector<Vec2> hull(std::vector<Vec2> p) {
  std::sort(p.begin(), p.end(), [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
  auto cross = [](const Vec2& o, const Vec2& a, const Vec2& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Vec2> h(2 * p.size());
  int k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (int i = int(p.size()) - 2, t = k + 1; i >= 0; --i) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  h.resize(std::max(0, k - 1));
  return h;
}

// The uncontrolled miss of the keyframes (the base's motion against the targets), as a multiple of the
// cloth tolerance (max(1 cm, 1 % of the sheet)) or of 10 cm for flocks.
double rms(const VecX& a, const VecX& b, const std::vector<int>& particles, int p) {
  double s = 0;
  int count = 0;
  for (int i = 0; i < p; ++i)
    if (particles.empty() || std::find(particles.begin(), particles.end(), i) != particles.end()) {
      s += (at(a, i) - at(b, i)).squaredNorm();
      ++count;
    }
  return std::sqrt(s / std::max(1, count));
}

Scene parse_base(const nlohmann::json& s, const std::filesystem::path& file) {
  nlohmann::json j = s;
  j["objectives"] = {{{"type", "center_of_mass"}, {"frame", 1}, {"target", {0, 0, 0}}}};
  return parse_scene(j.dump(), file);
}

}  // namespace

const std::vector<std::string>& reachable_classes() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const auto& c : kClasses) v.push_back(c.name);
    return v;
  }();
  return names;
}

bool reachable_class_on_character(const std::string& kind) { return kind.rfind("cape", 0) == 0 || kind == "poncho"; }

std::vector<std::pair<std::string, std::string>> reachable_suite(const ReachableSweepOptions& o) {
  // Each class gets its share of count (at least one), interleaved so a prefix covers every class; a class
  // outside the suite only when named, and then count scenes.
  std::vector<std::pair<std::string, int>> left;
  for (const auto& c : kClasses) {
    const bool named = std::find(o.classes.begin(), o.classes.end(), c.name) != o.classes.end();
    if (c.share == 0 ? named : o.classes.empty() || named)
      left.push_back({c.name, c.share == 0 ? o.count : std::max(1, int(std::lround(c.share * o.count / 100.0)))});
  }
  std::vector<std::pair<std::string, std::string>> suite;
  for (int i = 0;; ++i) {
    bool any = false;
    for (const auto& [name, n] : left)
      if (i < n) {
        suite.push_back({name + "-" + std::to_string(i), name});
        any = true;
      }
    if (!any) break;
  }
  return suite;
}

namespace {

// The base scene of class `kind` and its variant (no keyframes yet).
void draw_scene(const std::string& kind, Draw& d, int index, bool reduced, const std::filesystem::path& directory,
                ReachableScene& r) {
  nlohmann::json& s = r.scene;
  s["seed"] = d.integer(1, 1000000);
  if (kind.rfind("flock", 0) == 0) {
    const int agents = reduced ? 16 : d.integer(20, 100);
    const double a = d.uniform(0, 2 * M_PI), speed = d.uniform(0, 1.5);
    s["time"] = {{"fps", 15}, {"substeps", 2}, {"frames", reduced ? 15 : d.integer(20, 45)}};
    s["flock"] = {{"agents", agents},
                  {"spawn", {{"radius", 0.7 * std::sqrt(double(agents)) + 1.0},
                             {"velocity", {speed * std::cos(a), 0, speed * std::sin(a)}}}}};
    s["controls"] = {{"kind", index % 2 ? "per_step" : "per_frame"}};
    const double b = d.uniform(0, 2 * M_PI);
    r.variant.force = d.uniform(0.2, 0.6) * Vec3(std::cos(b), 0, std::sin(b));
  } else if (reachable_class_on_character(kind)) {
    r.character = true;
    sheet_on_character(kind, d, reduced, directory, s);
    s["controls"] = {{"kind", "per_frame"}};
    r.variant.dg = d.uniform(1.0, 3.0) * d.direction();
  } else {
    s["time"] = {{"fps", 30}, {"frames", reduced ? 15 : d.integer(20, 40)}};
    s["cloth"] = cloth_block(kind, d, index, reduced, r);
    if (r.thrown) {
      s["controls"] = {{"kind", "initial_velocity"}};
      r.variant.dv = d.uniform(0.3, 1.0) * d.direction();
      r.variant.omega = d.uniform(0.5, 2.0) * d.direction();
    } else {
      s["controls"] = {{"kind", index % 3 == 2 ? "per_step" : "per_frame"}};
      r.variant.dg = d.uniform(1.0, 3.0) * d.direction();
    }
  }
}

// The keyframes of one frame's variant positions, and the uncontrolled miss in tolerances.
struct Taken {
  nlohmann::json objectives = nlohmann::json::array();
  double worst = 0;
};

// A flock's keyframe at frame f: the hull of the variant's agents grown by a metre, or their centre of mass.
void flock_keyframe(const std::string& kind, int f, int p, const VecX& moved, const VecX& still, Taken& t) {
  if (kind == "flock-shape") {
    std::vector<Vec2> pts;
    Vec2 mean = Vec2::Zero();
    for (int i = 0; i < p; ++i) pts.push_back(Vec2(moved(3 * i), moved(3 * i + 2))), mean += pts.back() / p;
    nlohmann::json poly = nlohmann::json::array();
    for (const Vec2& q : hull(pts)) {
      const Vec2 out = q + 1.0 * (q - mean).normalized();  // a metre of margin around the agents
      poly.push_back({out.x(), out.y()});
    }
    t.objectives.push_back({{"type", "shape"}, {"frame", f}, {"polygon", poly}});
    int outside = 0;  // the uncontrolled agents outside the hull (roughly: farther than its radius)
    double radius = 0;
    for (const Vec2& q : pts) radius = std::max(radius, (q - mean).norm());
    for (int i = 0; i < p; ++i) outside += (Vec2(still(3 * i), still(3 * i + 2)) - mean).norm() > radius + 1.0;
    t.worst = std::max(t.worst, 20.0 * outside / p);
    return;
  }
  Vec3 c = Vec3::Zero(), c0 = Vec3::Zero();
  for (int i = 0; i < p; ++i) c += at(moved, i) / p, c0 += at(still, i) / p;
  t.objectives.push_back({{"type", "center_of_mass"}, {"frame", f}, {"target", vec(c)}});
  t.worst = std::max(t.worst, (c - c0).norm() / 0.1);
}

// A sheet's keyframe at frame f: a centre of mass or positions of all particles, an edge, a corner or a few.
void cloth_keyframe(Draw& pick, const Scene& base, int f, const VecX& rest, const VecX& moved, const VecX& still,
                    Taken& t) {
  const ClothSpec& cl = *base.cloth;
  const int p = base.particles();
  const std::vector<int> parts = keyframe_particles(pick, cl, rest, pick.integer(0, 3));
  const double tol = cloth_tolerance(base);
  if (parts.size() != 1 && pick.chance(0.5)) {
    Vec3 c = Vec3::Zero(), c0 = Vec3::Zero();
    int m = 0;
    for (int i = 0; i < p; ++i)
      if (parts.empty() || std::binary_search(parts.begin(), parts.end(), i)) c += at(moved, i), c0 += at(still, i), ++m;
    nlohmann::json o = {{"type", "center_of_mass"}, {"frame", f}, {"target", vec(c / m)}};
    if (!parts.empty()) o["particles"] = parts;
    t.objectives.push_back(o);
    t.worst = std::max(t.worst, (c - c0).norm() / m / tol);
    return;
  }
  std::vector<int> ps = parts;
  if (ps.empty())
    for (int i = 0; i < p; ++i)
      if (!std::binary_search(cl.pins.begin(), cl.pins.end(), i)) ps.push_back(i);
  nlohmann::json targets = nlohmann::json::array();
  for (int i : ps) targets.push_back(vec(at(moved, i)));
  t.objectives.push_back({{"type", "position"}, {"frame", f}, {"particles", ps}, {"targets", targets}});
  t.worst = std::max(t.worst, rms(moved, still, ps, p) / tol);
}

// One draw of a scene from hash h: the base scene, its variant enlarged until the uncontrolled motion misses some
// keyframe by three tolerances, and the keyframes taken from it.
struct Drawn {
  ReachableScene r;
  Scene base;
  std::vector<int> when;
  std::vector<VecX> moved;  // the variant's positions at every frame
  VecX rest;                // the base's positions at frame 0
};

Drawn draw_reachable(const std::string& kind, std::uint64_t h, int index, bool reduced,
                     const std::filesystem::path& directory) {
  Drawn out;
  ReachableScene& r = out.r;
  r.kind = kind;
  r.name = kind + "-" + std::to_string(index);
  Draw d(h);
  draw_scene(kind, d, index, reduced, directory, r);
  out.base = parse_base(r.scene, directory / (r.name + ".json"));
  const Scene& base = out.base;
  r.particles = base.particles();
  out.when = keyframe_frames(d, std::array<int, 4>{1, 2, 1, 3}[index % 4], base.time.frames);
  r.keyframes = int(out.when.size());
  const std::vector<VecX> still = simulate_variant(base, ReachableVariant{});
  out.rest = still[0];
  for (int attempt = 0;; ++attempt) {
    out.moved = simulate_variant(base, r.variant);
    Taken t;
    Draw pick(h + 17);
    for (int f : out.when) {
      if (base.flock) flock_keyframe(kind, f, base.particles(), out.moved[f], still[f], t);
      else cloth_keyframe(pick, base, f, out.rest, out.moved[f], still[f], t);
    }
    r.scene["objectives"] = t.objectives;
    if (t.worst >= 3 || attempt == 3) break;
    r.variant.dg *= 2, r.variant.dv *= 2, r.variant.omega *= 2, r.variant.force *= 2;
  }
  return out;
}

// How far a thousandth of the variant's change moves a drawn sheet's keyframes: the largest of the four
// perturbed_variant moves, in tolerances, measured on the keyframes' own particles (the same picks).
double conditioning(const Drawn& dr, std::uint64_t h) {
  double worst = 0;
  for (int how = 0; how < 4; ++how) {
    const std::vector<VecX> moved = simulate_variant(dr.base, perturbed_variant(dr.r.variant, 1e-3, how));
    Taken t;
    Draw pick(h + 17);
    for (int f : dr.when) cloth_keyframe(pick, dr.base, f, dr.rest, moved[f], dr.moved[f], t);
    worst = std::max(worst, t.worst);
  }
  return worst;
}

// Draws after the first for a knife edge. Ten of the twelve drops onto a collider at seed 52 are knife edges: at
// that rate 24 more draws leave one in a thousand still one.
constexpr int kMaxRedraws = 24;

}  // namespace

ReachableVariant perturbed_variant(const ReachableVariant& v, double eps, int how) {
  const auto turned = [&](const Vec3& c) -> Vec3 {
    if (c.norm() == 0) return c;
    if (how < 2) return c * (how == 0 ? 1 + eps : 1 - eps);
    const Vec3 a = std::abs(c.x()) < 0.6 * c.norm() ? Vec3::UnitX() : Vec3::UnitY();
    const Vec3 e1 = c.cross(a).normalized(), e2 = c.cross(e1).normalized();
    return c + eps * c.norm() * (how == 2 ? e1 : e2);
  };
  ReachableVariant p = v;
  p.dg = turned(v.dg), p.dv = turned(v.dv), p.omega = turned(v.omega), p.force = turned(v.force);
  return p;
}

ReachableScene generate_reachable(const std::string& kind, unsigned seed, int index, bool reduced,
                                  const std::filesystem::path& directory, bool well_conditioned) {
  if (std::find(reachable_classes().begin(), reachable_classes().end(), kind) == reachable_classes().end())
    throw std::invalid_argument("no reachable class " + kind);
  std::uint64_t h = seed * 0x100000001b3ull + std::uint64_t(index) * 7919;
  for (char ch : kind) h = (h ^ std::uint64_t(ch)) * 0x100000001b3ull;
  for (int redraw = 0;; ++redraw) {
    const std::uint64_t hr = redraw == 0 ? h : (h ^ (0x9e3779b97f4a7c15ull * std::uint64_t(redraw))) * 0x100000001b3ull;
    Drawn dr = draw_reachable(kind, hr, index, reduced, directory);
    if (!well_conditioned || dr.base.flock) return dr.r;
    dr.r.conditioning = conditioning(dr, hr);
    dr.r.redraws = redraw;
    if (dr.r.conditioning <= 1 || redraw == kMaxRedraws) return dr.r;
  }
}

VecX variant_step_force(const Scene& base, const ReachableVariant& variant) {
  auto sys = make_system(base);
  const int p = sys->particles();
  VecX u(3 * p);
  for (int i = 0; i < p; ++i)
    u.segment<3>(3 * i) = base.flock ? Vec3(variant.force) : Vec3(sys->masses()(i) * variant.dg);
  return u;
}

VecX variant_initial_velocity(const Scene& base, const ReachableVariant& variant) {
  auto sys = make_system(base);
  VecX x, v;
  sys->initial_state(x, v);
  if (!base.cloth || (variant.dv.isZero() && variant.omega.isZero())) return v;
  const std::vector<int>& pins = base.cloth->pins;
  Vec3 c = Vec3::Zero();
  int free = 0;
  for (int i = 0; i < sys->particles(); ++i)
    if (!std::binary_search(pins.begin(), pins.end(), i)) c += at(x, i), ++free;
  c /= std::max(1, free);
  for (int i = 0; i < sys->particles(); ++i)
    if (!std::binary_search(pins.begin(), pins.end(), i))
      v.segment<3>(3 * i) += variant.dv + variant.omega.cross(at(x, i) - c);
  return v;
}

std::vector<VecX> simulate_variant(const Scene& base, const ReachableVariant& variant) {
  auto sys = make_system(base);
  VecX x, v;
  sys->initial_state(x, v);
  v = variant_initial_velocity(base, variant);
  const VecX u = variant_step_force(base, variant);
  Rollout r;
  RolloutOptions options;
  options.tape = false;
  if (!simulate(*sys, x, v, base.time.steps(), [&](int) -> const VecX& { return u; }, r, options))
    throw std::runtime_error(base.name + ": the variant diverged at step " + std::to_string(r.diverged_at));
  std::vector<VecX> frames;
  for (int f = 0; f <= base.time.frames; ++f) frames.push_back(r.x[f * base.time.substeps]);
  return frames;
}

}  // namespace kf
