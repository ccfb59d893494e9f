#include "sim/cloth/cloth_springs.h"

namespace kf {

ClothSprings make_cloth_springs(const ClothSpec& spec, const VecX& x0) {
  ClothSprings out;
  const int nx = spec.nx, ny = spec.ny;
  auto add = [&](int a, int b, double k) {
    BucklingSpring s;
    s.a = a;
    s.b = b;
    s.rest = (seg(x0, b) - seg(x0, a)).norm();
    s.k = k;
    s.k_post = spec.buckle_stiffness * k;
    s.f_buckle = k * s.rest * spec.buckle_strain;
    s.transverse_ramp = spec.transverse_ramp;
    out.list.push_back(s);
  };
  // Type 1 (damped): structural, then shear.
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if (i + 1 < nx) add(spec.index(i, j), spec.index(i + 1, j), spec.stretch);
      if (j + 1 < ny) add(spec.index(i, j), spec.index(i, j + 1), spec.stretch);
    }
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      add(spec.index(i, j), spec.index(i + 1, j + 1), spec.shear);
      add(spec.index(i + 1, j), spec.index(i, j + 1), spec.shear);
    }
  out.damped = int(out.list.size());
  // Type 2: bending across two edges.
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if (i + 2 < nx) add(spec.index(i, j), spec.index(i + 2, j), spec.bend);
      if (j + 2 < ny) add(spec.index(i, j), spec.index(i, j + 2), spec.bend);
    }
  // Incidence in spring order per particle.
  const int p = spec.particles();
  std::vector<std::vector<ClothSprings::Incident>> inc(p);
  for (int k = 0; k < int(out.list.size()); ++k) {
    inc[out.list[k].a].push_back({k, +1, -1});
    inc[out.list[k].b].push_back({k, -1, -1});
  }
  out.incident_start.assign(1, 0);
  for (auto& l : inc) {
    out.incident.insert(out.incident.end(), l.begin(), l.end());
    out.incident_start.push_back(int(out.incident.size()));
  }
  return out;
}

}  // namespace kf
