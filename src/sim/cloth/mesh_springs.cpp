#include "sim/cloth/mesh_springs.h"

#include <algorithm>
#include <map>
#include <set>
#include <utility>

#include "core/error.h"

namespace kf {

namespace {
using Pair = std::pair<int, int>;
Pair ordered(int a, int b) { return a < b ? Pair{a, b} : Pair{b, a}; }

// The neighbour of corner `e` in face f other than `other` (f holds both, next to each other).
int far_neighbour(const std::vector<int>& f, int e, int other) {
  const int n = int(f.size());
  const int k = int(std::find(f.begin(), f.end(), e) - f.begin());
  const int prev = f[(k + n - 1) % n], next = f[(k + 1) % n];
  return prev == other ? next : prev;
}
}  // namespace

ClothSprings make_mesh_springs(const ClothSpec& spec, const ClothMesh& mesh, const VecX& x0) {
  std::set<Pair> joined;
  std::vector<Pair> stretch, shear, bend;
  std::map<Pair, std::vector<int>> edge_faces;
  for (int fi = 0; fi < int(mesh.faces.size()); ++fi) {
    const auto& f = mesh.faces[fi];
    const int n = int(f.size());
    for (int k = 0; k < n; ++k) edge_faces[ordered(f[k], f[(k + 1) % n])].push_back(fi);
  }
  for (const auto& [e, faces] : edge_faces) stretch.push_back(e);  // map order: sorted
  joined.insert(stretch.begin(), stretch.end());
  for (const auto& f : mesh.faces)
    if (f.size() == 4)
      for (const Pair d : {ordered(f[0], f[2]), ordered(f[1], f[3])})
        if (joined.insert(d).second) shear.push_back(d);
  std::sort(shear.begin(), shear.end());
  for (const auto& [e, faces] : edge_faces) {
    if (faces.size() != 2) continue;  // a boundary (or a non-manifold edge: no bending across it)
    const auto& f1 = mesh.faces[faces[0]];
    const auto& f2 = mesh.faces[faces[1]];
    for (const auto& [end, other] : {e, Pair{e.second, e.first}}) {
      const int c = far_neighbour(f1, end, other), d = far_neighbour(f2, end, other);
      if (c != d && joined.insert(ordered(c, d)).second) bend.push_back(ordered(c, d));
    }
  }
  std::sort(bend.begin(), bend.end());
  ClothSprings out;
  auto add = [&](const std::vector<Pair>& pairs, double k) {
    for (const auto& [a, b] : pairs) {
      out.list.push_back(make_buckling_spring(spec, x0, a, b, k));
      if (!(out.list.back().rest > 1e-9))
        throw InputError(mesh.file + ": vertices " + std::to_string(a) + " and " + std::to_string(b) +
                         " of the cloth mesh coincide (expected a welded mesh)");
    }
  };
  add(stretch, spec.stretch);
  add(shear, spec.shear);
  out.damped = int(out.list.size());
  add(bend, spec.bend);
  set_incidence(out, mesh.particles());
  return out;
}

}  // namespace kf
