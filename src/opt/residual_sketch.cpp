#include "opt/residual_sketch.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace kf {

namespace {

// The moments a sketched keyframe's displacement is measured by: 1, a, and a's quadratic terms over its
// particles' rest positions a (centred, scaled to unit RMS).
constexpr int kMoments = 10;

std::vector<std::array<double, kMoments>> moments(const PlacedKeyframe& p, const VecX& x0) {
  Vec3 c = Vec3::Zero();
  for (int i : p.ids) c += x0.segment<3>(3 * i);
  c /= double(p.ids.size());
  double r2 = 0;
  for (int i : p.ids) r2 += (x0.segment<3>(3 * i) - c).squaredNorm();
  const double scale = 1 / std::sqrt(std::max(1e-12, r2 / double(p.ids.size())));
  std::vector<std::array<double, kMoments>> out;
  for (int i : p.ids) {
    const Vec3 a = scale * (x0.segment<3>(3 * i) - c);
    out.push_back({1, a.x(), a.y(), a.z(), a.x() * a.x(), a.y() * a.y(), a.z() * a.z(), a.x() * a.y(), a.x() * a.z(),
                   a.y() * a.z()});
  }
  return out;
}

bool is_sketched(const PlacedKeyframe& p) { return !p.centroid && int(p.ids.size()) > kDenseKeyframeParticles; }

}  // namespace

bool sketched(const std::vector<PlacedKeyframe>& placed) {
  return std::any_of(placed.begin(), placed.end(), is_sketched);
}

Eigen::MatrixXd residual_sketch(const std::vector<PlacedKeyframe>& placed, const VecX& x0, const VecX& r) {
  const long n = residual_count(placed);
  if (!sketched(placed)) return Eigen::MatrixXd::Identity(n, n);
  std::vector<VecX> rows;
  if (r.size() == n && r.norm() > 0) rows.push_back(r);  // first: it is never dropped as dependent
  long offset = 0;
  for (const PlacedKeyframe& p : placed) {
    if (!is_sketched(p)) {
      for (long k = 0; k < p.rows(); ++k) {
        rows.push_back(VecX::Zero(n));
        rows.back()[offset + k] = 1;
      }
    } else {
      const auto m = moments(p, x0);
      for (int f = 0; f < kMoments; ++f) {
        for (int axis = 0; axis < 3; ++axis) {
          VecX row = VecX::Zero(n);
          for (size_t j = 0; j < m.size(); ++j) row[offset + 3 * long(j) + axis] = m[j][size_t(f)];
          rows.push_back(std::move(row));
        }
      }
    }
    offset += p.rows();
  }
  // Modified Gram–Schmidt, twice for accuracy; a combination dependent on the ones before is dropped.
  std::vector<VecX> basis;
  for (VecX v : rows) {
    const double norm0 = v.norm();
    for (int pass = 0; pass < 2; ++pass)
      for (const VecX& b : basis) v -= b.dot(v) * b;
    const double norm = v.norm();
    if (norm > 1e-8 * norm0 && norm0 > 0) basis.push_back(v / norm);
  }
  Eigen::MatrixXd s(long(basis.size()), n);
  for (size_t k = 0; k < basis.size(); ++k) s.row(long(k)) = basis[k].transpose();
  return s;
}

}  // namespace kf
