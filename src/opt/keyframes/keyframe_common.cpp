#include "opt/keyframes/keyframe_common.h"

#include <algorithm>
#include <cstdio>

namespace kf {

std::vector<int> keyframe_members(const ObjectiveSpec& s, int particles) {
  if (!s.particles.empty()) return s.particles;
  std::vector<int> all(particles);
  for (int i = 0; i < particles; ++i) all[i] = i;
  return all;
}

Vec3 mean_of(const VecX& x, const std::vector<int>& ids) {
  Vec3 m = Vec3::Zero();
  if (ids.empty()) {
    for (int i = 0; i < x.size() / 3; ++i) m += seg(x, i);
    return m / double(x.size() / 3);
  }
  for (int i : ids) m += seg(x, i);
  return m / double(ids.size());
}

double sheet_width(const Scene& scene, const VecX& x0) {
  if (!scene.cloth || !scene.cloth->mesh) {
    const int nx = scene.cloth ? scene.cloth->nx : 1;
    return (seg(x0, nx - 1) - seg(x0, 0)).norm();
  }
  const Eigen::Map<const Eigen::Matrix<double, 3, Eigen::Dynamic>> p(x0.data(), 3, x0.size() / 3);
  return (p.rowwise().maxCoeff() - p.rowwise().minCoeff()).maxCoeff();
}

double cloth_tolerance(const Scene& scene) {
  const double sheet = scene.cloth ? std::max(scene.cloth->width, scene.cloth->height) : 0.0;
  return std::max(0.01, 0.01 * sheet);
}

std::string format_number(const char* fmt, double a, double b) {
  char buf[1024];
  std::snprintf(buf, sizeof buf, fmt, a, b);
  return buf;
}

std::string centimetres(double metres) { return format_number("%.2f cm", 100 * metres); }

void judge_distance(KeyframeMeasure& m, double error, double tolerance) {
  m.judged = true;
  m.miss = error / tolerance;
  m.error = centimetres(error);
  m.tolerance = centimetres(tolerance);
}

double target_squared_error(const ObjectiveSpec& o, const std::vector<Vec3>& targets, const VecX& q, int& n) {
  double sum = 0;
  n = o.particles.empty() ? int(q.size() / 3) : int(o.particles.size());
  for (int j = 0; j < n; ++j) {
    const int i = o.particles.empty() ? j : o.particles[j];
    sum += (seg(q, i) - targets[targets.size() == 1 ? 0 : j]).squaredNorm();
  }
  return sum;
}

double TargetsTerm::eval(const VecX& x, const VecX& v, VecX& gx, VecX& gv) const {
  const VecX& q = on_velocity_ ? v : x;
  VecX& g = on_velocity_ ? gv : gx;
  long double val = 0;  // extended: round-off in φ sets the floor of a finite-difference check
  for (size_t k = 0; k < ids_.size(); ++k) {
    const Vec3 d = seg(q, ids_[k]) - targets_[targets_.size() == 1 ? 0 : k];
    val += 0.5 * w_ * d.squaredNorm();
    seg(g, ids_[k]) += w_ * d;
  }
  return double(val);
}

}  // namespace kf
