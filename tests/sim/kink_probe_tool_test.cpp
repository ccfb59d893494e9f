// Measuring tool: what makes φ kinked along the negative gradient at a run's controls (a cloth on a
// character). It evaluates φ and its slope along the line, records the discrete state of each rollout (every
// particle's body contact zone, closest triangle, feature and point at each step; PCG iterations, split
// substeps and self contacts per step), names the discrete changes between neighbouring points, and bisects
// the first interval where φ departs from its slopes down to the change that makes the jump.
// Run with KEYFRAME_NO_FP_TRAPS=1 (Embree's point queries) --gtest_also_run_disabled_tests
// --gtest_filter='KinkProbeTool.*' and
//   KF_KINK_SCENE=scene.json KF_KINK_RUN=run_dir KF_KINK_OUT=out.json
//   [KF_KINK_SOLVER=direct] [KF_KINK_POINTS=41] [KF_KINK_MIN=1e-10] [KF_KINK_MAX=1e-5] [KF_KINK_BISECT=40]
//   [KF_KINK_RAMP=cloth.contact_ramp] [KF_KINK_STIFFNESS=character.body.stiffness] [KF_KINK_AT_START=1]
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "app/uncontrolled_targets.h"
#include "opt/controls_file.h"
#include "opt/problem.h"
#include "opt/schedule_file.h"
#include "scene/scene.h"
#include "sim/cape/cape_system.h"
#include "sim/make_system.h"

namespace kf {
namespace {

// Where a particle is against the body at a step's start: beyond the query (none), outside the contact
// layer (out), in the stiffness ramp (ramp), at full stiffness (full), deeper inside than `search` (cut: no
// force).
enum Zone : char { kNone, kOut, kRamp, kFull, kCut };
const char* zone_name(int z) {
  static const char* names[] = {"none", "out", "ramp", "full", "cut"};
  return names[z];
}

struct ParticleAtStep {
  Zone zone = kNone;
  int triangle = -1;
  int feature = 0;
  double phi = 0, distance = 0;
  Vec3 x = Vec3::Zero(), point = Vec3::Zero(), force = Vec3::Zero();
};

struct RolloutState {
  int steps = 0, particles = 0;
  std::vector<ParticleAtStep> at;  // steps x particles
  std::vector<int> cg, substeps;
  double self_contacts = 0, body_contacts = 0;
  ParticleAtStep& operator()(int n, int i) { return at[size_t(n) * particles + i]; }
  const ParticleAtStep& operator()(int n, int i) const { return at[size_t(n) * particles + i]; }
};

// The cape system, recording each forward step's discrete state.
class ProbeSystem final : public System {
 public:
  ProbeSystem(CapeSystem& inner, double thickness, double search, double ramp, int steps)
      : inner_(inner), thickness_(thickness), search_(search), ramp_(ramp) {
    state.steps = steps;
    state.particles = inner.particles();
    state.at.resize(size_t(steps) * state.particles);
    state.cg.assign(steps, 0);
    state.substeps.assign(steps, 0);
  }
  int particles() const override { return inner_.particles(); }
  double h() const override { return inner_.h(); }
  const VecX& masses() const override { return inner_.masses(); }
  void initial_state(VecX& x, VecX& v) const override { inner_.initial_state(x, v); }
  std::unique_ptr<StepRecord> new_record() const override { return inner_.new_record(); }
  std::size_t record_bytes_estimate() const override { return inner_.record_bytes_estimate(); }
  using System::step;
  using System::step_adjoint;
  bool step(int n, const VecX& x, const VecX& v, const VecX& u, VecX& x1, VecX& v1, StepRecord& r) override {
    const bool ok = inner_.step(n, x, v, u, x1, v1, r);
    if (n < state.steps) record(n, x);
    return ok;
  }
  void step_adjoint(int n, const VecX& x, const VecX& v, const VecX& u, const StepRecord& r, const VecX& xh1,
                    const VecX& vh1, VecX& xh, VecX& vh, VecX& uh) override {
    inner_.step_adjoint(n, x, v, u, r, xh1, vh1, xh, vh, uh);
  }
  void save_step_context(int n, VecX& c) const override { inner_.save_step_context(n, c); }
  void restore_step_context(int n, const VecX& c) override { inner_.restore_step_context(n, c); }
  std::string describe() const override { return inner_.describe(); }
  std::string divergence_reason() const override { return inner_.divergence_reason(); }
  StepSchedule step_schedule() const override { return inner_.step_schedule(); }
  void hold_step_schedule(const StepSchedule& s) override { inner_.hold_step_schedule(s); }
  void release_step_schedule() override { inner_.release_step_schedule(); }
  std::vector<std::pair<std::string, double>> run_stats() const override { return inner_.run_stats(); }

  RolloutState state;

 private:
  // The body is posed at step n once the step has run; the contact force is taken at the step's start x.
  void record(int n, const VecX& x) {
    state.cg[n] = inner_.cloth().last_cg_iterations();
    state.substeps[n] = inner_.cloth().last_substeps();
    const BodyCollider& body = inner_.body_collider();
    for (int i = 0; i < state.particles; ++i) {
      ParticleAtStep& s = state(n, i);
      s = ParticleAtStep{};
      s.x = seg(x, i);
      if (inner_.cloth().pinned(i)) continue;  // a pin goes to its track whatever its contact
      const BodyHit hit = body.query().closest(s.x, std::max(thickness_, search_));
      if (!hit.found()) continue;
      s.triangle = hit.triangle;
      s.feature = int(hit.feature);
      s.phi = hit.signed_distance;
      s.distance = hit.distance;
      s.point = hit.point;
      s.zone = s.phi >= thickness_ ? kOut : s.phi < -search_ ? kCut : s.phi > thickness_ - ramp_ ? kRamp : kFull;
      ContactForce c;
      if (body.contact(n, s.x, Vec3::Zero(), true, c)) s.force = c.f;
    }
  }
  CapeSystem& inner_;
  double thickness_, search_, ramp_;
};

struct Point {
  double t = 0, phi = 0, slope = 0;
  RolloutState state;
};

double stat(const std::vector<std::pair<std::string, double>>& stats, const std::string& key) {
  for (const auto& [k, v] : stats)
    if (k == key) return v;
  return 0;
}

// The discrete changes from a to b, by kind, with the first (earliest step) of each and the largest change of
// contact force each kind brings.
nlohmann::json changes(const RolloutState& a, const RolloutState& b) {
  struct Kind {
    int count = 0, first_step = -1, first_particle = -1;
    double max_force_jump = 0;
    std::string example;
  };
  std::map<std::string, Kind> kinds;
  auto note = [&](const std::string& kind, int n, int i, double df, const std::string& what) {
    Kind& k = kinds[kind];
    ++k.count;
    if (k.first_step < 0 || n < k.first_step) k.first_step = n, k.first_particle = i, k.example = what;
    k.max_force_jump = std::max(k.max_force_jump, df);
  };
  for (int n = 0; n < a.steps; ++n) {
    if (a.cg[n] != b.cg[n]) note("pcg_iterations", n, -1, 0, std::to_string(a.cg[n]) + " -> " + std::to_string(b.cg[n]));
    if (a.substeps[n] != b.substeps[n])
      note("substeps", n, -1, 0, std::to_string(a.substeps[n]) + " -> " + std::to_string(b.substeps[n]));
    for (int i = 0; i < a.particles; ++i) {
      const ParticleAtStep &p = a(n, i), &q = b(n, i);
      const double df = (p.force - q.force).norm(), dx = (p.x - q.x).norm();
      const bool touching = p.force.norm() > 0 || q.force.norm() > 0;
      if (p.zone != q.zone) {
        std::string what = std::string(zone_name(p.zone)) + " -> " + zone_name(q.zone);
        const bool cut = p.zone == kCut || q.zone == kCut || ((p.zone == kNone) != (q.zone == kNone) && touching);
        note(cut ? "zone_cut_off" : "zone_" + std::string(zone_name(std::min(p.zone, q.zone))) + "_" +
                                        zone_name(std::max(p.zone, q.zone)),
             n, i, df, what + " phi " + std::to_string(p.phi) + " -> " + std::to_string(q.phi));
      }
      if (p.zone == kNone || q.zone == kNone) continue;
      if ((p.phi < 0) != (q.phi < 0) && std::min(std::abs(p.phi), std::abs(q.phi)) > 1e-5)
        note("inside_outside_flip", n, i, df, "phi " + std::to_string(p.phi) + " -> " + std::to_string(q.phi));
      const double jump = (p.point - q.point).norm();
      if (touching && jump > 1e-7 + 100 * dx)
        note("closest_point_jump", n, i, df,
             "triangle " + std::to_string(p.triangle) + " feature " + std::to_string(p.feature) + " -> " +
                 std::to_string(q.triangle) + " feature " + std::to_string(q.feature) + ", point moved " +
                 std::to_string(jump) + " m, particle " + std::to_string(dx) + " m, phi " + std::to_string(p.phi));
      else if (touching && (p.triangle != q.triangle || p.feature != q.feature))
        note("feature_change_continuous", n, i, df, "");
    }
  }
  if (a.self_contacts != b.self_contacts) note("self_contacts", -1, -1, 0, "");
  nlohmann::json j = nlohmann::json::object();
  for (const auto& [name, k] : kinds)
    j[name] = {{"count", k.count},           {"first_step", k.first_step}, {"first_particle", k.first_particle},
               {"max_force_jump", k.max_force_jump}, {"example", k.example}};
  return j;
}

// φ(b) - φ(a) less the trapezoid of the slopes: ~0 where φ is smooth between them.
double anomaly(const Point& a, const Point& b) { return (b.phi - a.phi) - 0.5 * (a.slope + b.slope) * (b.t - a.t); }

nlohmann::json zones(const RolloutState& s) {
  int count[5] = {0, 0, 0, 0, 0};
  for (const auto& p : s.at) ++count[p.zone];
  nlohmann::json j;
  for (int z = 0; z < 5; ++z) j[zone_name(z)] = count[z];
  long cg = 0;
  for (int c : s.cg) cg += c;
  // The contact whose direction turns fastest as the particle moves: |f| / distance on an edge or a vertex
  // (the exact df/dx's curvature part; zero on a face).
  double sharpest = 0;
  nlohmann::json where;
  std::vector<double> bends;
  for (int n = 0; n < s.steps; ++n)
    for (int i = 0; i < s.particles; ++i) {
      const ParticleAtStep& p = s(n, i);
      if (p.feature == 0 || p.force.norm() == 0) continue;
      const double bend = p.force.norm() / std::max(p.distance, 1e-12);
      bends.push_back(bend);
      if (bend > sharpest)
        sharpest = bend, where = {{"step", n}, {"particle", i}, {"distance", p.distance}, {"phi", p.phi},
                                  {"feature", p.feature}, {"triangle", p.triangle}, {"force", p.force.norm()}};
    }
  j["edge_vertex_contacts"] = bends.size();
  j["sharpest_bend"] = sharpest;
  j["sharpest_at"] = where;
  int over = 0;
  for (double b : bends) over += b > 1e5;
  j["bends_over_1e5"] = over;
  j["pcg_iterations"] = cg;
  j["self_contacts"] = s.self_contacts;
  return j;
}

// The scene a probe runs: KF_KINK_SOLVER "direct", KF_KINK_RAMP and KF_KINK_STIFFNESS override its keys.
Scene probe_scene(const char* file) {
  Scene scene = load_scene(file);
  const std::string solver = std::getenv("KF_KINK_SOLVER") ? std::getenv("KF_KINK_SOLVER") : "scene";
  if (solver == "direct") scene.cloth->solver = "direct";
  if (std::getenv("KF_KINK_RAMP")) scene.cloth->contact_ramp = std::atof(std::getenv("KF_KINK_RAMP"));
  if (std::getenv("KF_KINK_STIFFNESS")) scene.character->body_stiffness = std::atof(std::getenv("KF_KINK_STIFFNESS"));
  resolve_uncontrolled_offsets(scene);
  return scene;
}

TEST(KinkProbeTool, DISABLED_Measure) {
  const char* file = std::getenv("KF_KINK_SCENE");
  const char* run = std::getenv("KF_KINK_RUN");
  const char* out = std::getenv("KF_KINK_OUT");
  ASSERT_TRUE(file && run && out);
  auto env = [](const char* k, double d) { return std::getenv(k) ? std::atof(std::getenv(k)) : d; };
  Scene scene = probe_scene(file);
  ASSERT_TRUE(scene.character.has_value());
  auto made = make_system(scene, scene.time.h());
  auto* cape = dynamic_cast<CapeSystem*>(made.get());
  ASSERT_NE(cape, nullptr);
  const CharacterSpec& ch = *scene.character;
  ProbeSystem sys(*cape, ch.body_thickness, ch.body_search, scene.cloth->contact_ramp * ch.body_thickness,
                  scene.time.steps());
  Problem problem(scene, scene.time, sys);
  int substeps = 0;
  // KF_KINK_AT_START=1: at the scene's initial guess (the run's first point) under the schedule it records.
  const bool at_start = std::getenv("KF_KINK_AT_START") && std::atoi(std::getenv("KF_KINK_AT_START"));
  const VecX z = at_start ? problem.initial_guess() : load_controls(std::filesystem::path(run) / "controls.bin", &substeps);
  ASSERT_EQ(z.size(), problem.size());
  if (at_start) {
    problem.evaluate(z, nullptr);
    sys.hold_step_schedule(sys.step_schedule());
  } else if (const StepSchedule s = run_schedule(run, scene, z, substeps); !s.empty()) {
    sys.hold_step_schedule(s);
  }

  VecX g(z.size());
  auto at = [&](double t, const VecX& d) {
    Point p;
    p.t = t;
    p.phi = problem.evaluate(VecX(z + t * d), &g);
    p.slope = g.dot(d);
    p.state = sys.state;
    p.state.self_contacts = stat(sys.run_stats(), "self_contacts");
    p.state.body_contacts = stat(sys.run_stats(), "body_contacts");
    return p;
  };
  problem.evaluate(z, &g);
  const double scale = std::max(1.0, z.lpNorm<Eigen::Infinity>());
  const VecX d = -(scale / g.norm()) * g;  // t is relative to max(1, |z|inf), as keyframe gradcheck's line
  const int points = int(env("KF_KINK_POINTS", 41));
  const double lo = env("KF_KINK_MIN", 1e-10), hi = env("KF_KINK_MAX", 1e-5);
  std::vector<Point> line;
  line.push_back(at(0, d));
  for (int k = 0; k < points; ++k) line.push_back(at(lo * std::pow(hi / lo, double(k) / (points - 1)), d));

  nlohmann::json j;
  j["scene"] = file;
  j["run"] = run;
  j["solver"] = scene.cloth->solver;
  j["phi"] = line[0].phi;
  j["slope_at_start"] = line[0].slope;
  j["step_unit"] = scale;
  j["start"] = zones(line[0].state);
  nlohmann::json rows = nlohmann::json::array();
  int first_bad = -1;
  for (size_t k = 1; k < line.size(); ++k) {
    const Point &a = line[k - 1], &b = line[k];
    const double r = anomaly(a, b), smooth = std::max(std::abs(b.phi - a.phi), std::abs(0.5 * (a.slope + b.slope) * (b.t - a.t)));
    const bool bad = std::abs(r) > 0.25 * smooth && std::abs(r) > 1e-12;
    if (bad && first_bad < 0) first_bad = int(k);
    rows.push_back({{"t", b.t}, {"phi", b.phi}, {"slope", b.slope}, {"predicted", line[0].phi + line[0].slope * b.t},
                    {"anomaly", r}, {"smooth_change", smooth}, {"departs", bad}, {"zones", zones(b.state)},
                    {"changes_since_previous", changes(a.state, b.state)}});
  }
  j["line"] = rows;

  // Bisect the first interval that departs: keep the half with the larger anomaly.
  if (first_bad > 0) {
    Point a = line[first_bad - 1], b = line[first_bad];
    nlohmann::json steps = nlohmann::json::array();
    for (int it = 0; it < int(env("KF_KINK_BISECT", 40)) && (b.t - a.t) > 1e-15 * std::max(1.0, b.t); ++it) {
      Point m = at(0.5 * (a.t + b.t), d);
      const double ra = anomaly(a, m), rb = anomaly(m, b);
      if (std::abs(ra) >= std::abs(rb)) b = std::move(m);
      else a = std::move(m);
      steps.push_back({{"from", a.t}, {"to", b.t}, {"phi_jump", b.phi - a.phi}, {"anomaly", anomaly(a, b)},
                       {"slope_from", a.slope}, {"slope_to", b.slope}});
    }
    j["bisection"] = {{"steps", steps},
                      {"from", a.t},
                      {"to", b.t},
                      {"phi_from", a.phi},
                      {"phi_to", b.phi},
                      {"slope_from", a.slope},
                      {"slope_to", b.slope},
                      {"anomaly", anomaly(a, b)},
                      {"changes", changes(a.state, b.state)}};
  }
  std::ofstream(out) << j.dump(1) << "\n";
}

}  // namespace
}  // namespace kf

namespace kf {
namespace {

// Where the rollout first responds nonlinearly along the line: per step, the second difference of the
// states at t = 0, T/2, T against their first difference, and the particle that carries most of it.
// KF_KINK_T (default 4e-10) sets T.
TEST(KinkProbeTool, DISABLED_Nonlinearity) {
  const char* file = std::getenv("KF_KINK_SCENE");
  const char* run = std::getenv("KF_KINK_RUN");
  const char* out = std::getenv("KF_KINK_OUT");
  ASSERT_TRUE(file && run && out);
  Scene scene = probe_scene(file);
  auto made = make_system(scene, scene.time.h());
  auto* cape = dynamic_cast<CapeSystem*>(made.get());
  ASSERT_NE(cape, nullptr);
  const CharacterSpec& ch = *scene.character;
  ProbeSystem sys(*cape, ch.body_thickness, ch.body_search, scene.cloth->contact_ramp * ch.body_thickness,
                  scene.time.steps());
  Problem problem(scene, scene.time, sys);
  int substeps = 0;
  const bool at_start = std::getenv("KF_KINK_AT_START") && std::atoi(std::getenv("KF_KINK_AT_START"));
  const VecX z = at_start ? problem.initial_guess() : load_controls(std::filesystem::path(run) / "controls.bin", &substeps);
  if (at_start) {
    problem.evaluate(z, nullptr);
    sys.hold_step_schedule(sys.step_schedule());
  } else if (const StepSchedule s = run_schedule(run, scene, z, substeps); !s.empty()) {
    sys.hold_step_schedule(s);
  }
  VecX g(z.size());
  problem.evaluate(z, &g);
  const VecX d = -g / g.norm();
  const double T = std::getenv("KF_KINK_T") ? std::atof(std::getenv("KF_KINK_T")) : 4e-10;
  std::vector<std::vector<VecX>> xs;
  std::vector<RolloutState> states;
  for (double t : {0.0, 0.5 * T, T}) {
    problem.evaluate(VecX(z + t * d), nullptr);
    xs.push_back(problem.rollout().x);
    states.push_back(sys.state);
  }
  nlohmann::json rows = nlohmann::json::array();
  const int p = sys.particles();
  for (size_t n = 1; n < xs[0].size(); ++n) {
    const VecX d1 = xs[2][n] - xs[0][n], d2 = xs[2][n] - 2 * xs[1][n] + xs[0][n];
    int worst = 0;
    for (int i = 1; i < p; ++i)
      if (seg(d2, i).norm() > seg(d2, worst).norm()) worst = i;
    nlohmann::json row = {{"step", n}, {"first_difference", d1.norm()}, {"second_difference", d2.norm()},
                          {"ratio", d2.norm() / std::max(d1.norm(), 1e-300)}, {"particle", worst},
                          {"particle_first", seg(d1, worst).norm()}, {"particle_second", seg(d2, worst).norm()}};
    if (n - 1 < size_t(states[0].steps)) {
      const ParticleAtStep& s = states[0](int(n) - 1, worst);
      row["zone_at_step_start"] = zone_name(s.zone);
      row["phi"] = s.phi;
      row["feature"] = s.feature;
      row["triangle"] = s.triangle;
      row["pcg_iterations"] = states[0].cg[n - 1];
    }
    rows.push_back(row);
  }
  std::ofstream(out) << nlohmann::json{{"scene", file}, {"run", run}, {"T", T}, {"steps", rows}}.dump(1) << "\n";
}

}  // namespace
}  // namespace kf
