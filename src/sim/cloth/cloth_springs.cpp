#include "sim/cloth/cloth_springs.h"

#include "sim/cloth/mesh_springs.h"

namespace kf {

BucklingSpring make_buckling_spring(const ClothSpec& spec, const VecX& x0, int a, int b, double k) {
  BucklingSpring s;
  s.a = a;
  s.b = b;
  s.rest = (seg(x0, b) - seg(x0, a)).norm();
  s.k = k;
  s.k_post = spec.buckle_stiffness * k;
  s.f_buckle = k * s.rest * spec.buckle_strain;
  s.transverse_ramp = spec.transverse_ramp;
  return s;
}

void set_incidence(ClothSprings& out, int p) {
  std::vector<std::vector<ClothSprings::Incident>> inc(p);
  for (int k = 0; k < int(out.list.size()); ++k) {
    inc[out.list[k].a].push_back({k, +1, -1});
    inc[out.list[k].b].push_back({k, -1, -1});
  }
  out.incident_start.assign(1, 0);
  out.incident.clear();
  for (auto& l : inc) {
    out.incident.insert(out.incident.end(), l.begin(), l.end());
    out.incident_start.push_back(int(out.incident.size()));
  }
}

ClothSprings make_cloth_springs(const ClothSpec& spec, const VecX& x0) {
  if (spec.mesh) return make_mesh_springs(spec, *spec.mesh, x0);
  ClothSprings out;
  const int nx = spec.nx, ny = spec.ny;
  auto add = [&](int a, int b, double k) { out.list.push_back(make_buckling_spring(spec, x0, a, b, k)); };
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
  set_incidence(out, spec.particles());
  return out;
}

}  // namespace kf
