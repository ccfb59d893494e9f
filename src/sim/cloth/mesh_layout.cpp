#include "sim/cloth/mesh_layout.h"

#include <Eigen/Geometry>
#include <random>

#include "core/error.h"

namespace kf {

namespace {
// Twice the vector area of a polygon (Newell's sum, about its first corner): its normal times twice its area.
Vec3 newell(const std::vector<int>& f, const VecX& x) {
  Vec3 n = Vec3::Zero();
  const Vec3 o = seg(x, f[0]);
  for (size_t k = 1; k + 1 < f.size(); ++k) n += (Vec3(seg(x, f[k])) - o).cross(Vec3(seg(x, f[k + 1])) - o);
  return n;
}

VecX stacked(const std::vector<Vec3>& v) {
  VecX x(3 * v.size());
  for (size_t i = 0; i < v.size(); ++i) seg(x, int(i)) = v[i];
  return x;
}
}  // namespace

std::vector<Vec3> mesh_vertex_normals(const ClothMesh& mesh, const VecX& x) {
  std::vector<Vec3> sum(mesh.vertices.size(), Vec3::Zero());
  for (const auto& f : mesh.faces) {
    const Vec3 n = newell(f, x);
    for (int v : f) sum[size_t(v)] += n;
  }
  for (Vec3& n : sum) n = n.norm() > 1e-300 ? Vec3(n.normalized()) : Vec3::UnitY();
  return sum;
}

VecX mesh_rest_positions(const ClothSpec& spec) {
  const ClothMesh& mesh = *spec.mesh;
  VecX x = stacked(mesh.vertices);
  if (spec.imperfection == 0) return x;
  const std::vector<Vec3> normal = mesh_vertex_normals(mesh, x);
  std::vector<char> moves(normal.size(), 1);
  for (int i : spec.pins)
    if (i >= 0 && i < int(moves.size())) moves[size_t(i)] = 0;
  // The same draws as add_imperfection (imperfection.cpp), each along its own vertex's normal.
  std::mt19937_64 rng(uint64_t(spec.imperfection_seed));
  for (size_t i = 0; i < normal.size(); ++i) {
    const double unit = double(rng() >> 11) * 0x1.0p-53;
    if (moves[i]) seg(x, int(i)) += spec.imperfection * (2 * unit - 1) * normal[i];
  }
  return x;
}

VecX mesh_masses(const ClothSpec& spec) {
  const ClothMesh& mesh = *spec.mesh;
  const int p = mesh.particles();
  VecX m = VecX::Constant(p, spec.mass / p);
  if (!spec.mass_by_area) return m;
  const VecX x = stacked(mesh.vertices);
  m.setZero();
  for (const auto& f : mesh.faces) {
    const double share = 0.5 * newell(f, x).norm() / double(f.size());
    for (int v : f) m[v] += share;
  }
  const double total = m.sum();
  for (int i = 0; i < p; ++i)
    if (!(m[i] > 1e-9 * total))
      throw InputError(mesh.file + ": vertex " + std::to_string(i) + " of the cloth mesh has no area around it");
  return m * (spec.mass / total);
}

}  // namespace kf
