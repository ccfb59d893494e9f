#include "scene/cloth_mesh_spec.h"

#include <Eigen/Geometry>
#include <cmath>

#include "core/error.h"
#include "scene/cloth_spec.h"
#include "scene/params.h"

namespace kf {

std::shared_ptr<const ClothMesh> parse_cloth_mesh(Block b, const std::filesystem::path& directory) {
  const std::string file = b.string("file");
  const std::string name = b.string("name", "");
  const double scale = b.number("scale", 1.0, 1e-6, 1e6);
  const bool z_up = b.string("up_axis", "y", {"y", "z"}) == "z";
  Eigen::AngleAxisd rotation(0.0, Vec3::UnitY());
  if (auto r = b.optional_child("rotation")) {
    const Vec3 axis = r->vec3("axis", Vec3::UnitY(), -1e3, 1e3);
    if (axis.norm() < 1e-9) r->fail("axis", "expected a non-zero direction");
    rotation = Eigen::AngleAxisd(r->number("degrees", 0.0, -360.0, 360.0) * M_PI / 180.0, axis.normalized());
    r->finish();
  }
  const Vec3 offset = b.vec3("offset", Vec3::Zero());
  const std::filesystem::path path = directory / file;
  std::shared_ptr<ClothMesh> mesh;
  try {
    mesh = std::make_shared<ClothMesh>(read_cloth_mesh(path, name));
  } catch (const InputError& e) {
    b.fail("file", e.what());  // the scene's file and field before the mesh file's own message
  }
  const Mat3 R = rotation.toRotationMatrix();
  for (Vec3& p : mesh->vertices) {
    if (z_up) p = Vec3(p.x(), p.z(), -p.y());
    p = R * (scale * p) + offset;
    if (!p.allFinite() || p.cwiseAbs().maxCoeff() > 1e6) b.fail("scale", "expected the mesh within 1e6 m of the origin");
  }
  // Springs need lengths and masses need areas: every face edge longer than a nanometre, every vertex in a
  // face with an area.
  std::vector<char> has_area(mesh->vertices.size(), 0);
  for (const auto& f : mesh->faces) {
    Vec3 n = Vec3::Zero();
    for (size_t k = 0; k < f.size(); ++k) {
      const Vec3 &p = mesh->vertices[size_t(f[k])], &q = mesh->vertices[size_t(f[(k + 1) % f.size()])];
      if ((q - p).norm() <= 1e-9)
        throw InputError(mesh->file + ": vertices " + std::to_string(f[k]) + " and " +
                         std::to_string(f[(k + 1) % f.size()]) + " coincide (expected a welded mesh)");
      if (k + 2 < f.size()) n += (mesh->vertices[size_t(f[k + 1])] - mesh->vertices[size_t(f[0])]).cross(
                                mesh->vertices[size_t(f[k + 2])] - mesh->vertices[size_t(f[0])]);
    }
    if (n.norm() > 1e-18)
      for (int v : f) has_area[size_t(v)] = 1;
  }
  for (size_t v = 0; v < has_area.size(); ++v)
    if (!has_area[v]) throw InputError(mesh->file + ": vertex " + std::to_string(v) + " is in no face with an area");
  b.finish();
  return mesh;
}

Vec3 cloth_rest_position(const ClothSpec& c, int particle) {
  if (c.mesh) return c.mesh->vertices[size_t(particle)];
  const double dx = c.nx > 1 ? c.width / (c.nx - 1) : 0.0, dy = c.ny > 1 ? c.height / (c.ny - 1) : 0.0;
  return c.origin + (particle % c.nx) * dx * c.u_axis + (particle / c.nx) * dy * c.v_axis;
}

bool is_rest_box(const nlohmann::json& set) {
  return set.is_object() && (set.contains("min") || set.contains("max"));
}

std::vector<int> particles_in_region(Block& b, const ClothSpec& c) {
  const Vec3 lo = b.vec3("min"), hi = b.vec3("max");
  if ((hi - lo).minCoeff() < 0) b.fail("max", "expected every coordinate at least \"min\"'s");
  b.finish();
  std::vector<int> out;
  for (int i = 0; i < c.particles(); ++i) {
    const Vec3 p = cloth_rest_position(c, i);
    if ((p - lo).minCoeff() >= 0 && (hi - p).minCoeff() >= 0) out.push_back(i);
  }
  if (out.empty()) b.fail("min", "expected a box that holds at least one particle's rest position");
  return out;
}

bool is_group_set(const nlohmann::json& set) { return set.is_object() && set.contains("group"); }

std::vector<int> particles_in_group(Block& b, const ClothSpec& c) {
  const std::string name = b.string("group");
  b.finish();
  if (!c.mesh) b.fail("group", "expected a mesh cloth (cloth.mesh): a grid names no vertex sets");
  const auto it = c.mesh->groups.find(name);
  if (it != c.mesh->groups.end()) return it->second;
  std::string list;
  for (const auto& [n, set] : c.mesh->groups) list += (list.empty() ? "\"" : ", \"") + n + "\"";
  b.fail("group", "expected a vertex set " + c.mesh->file + " names (it names " +
                      (list.empty() ? std::string("none: OBJ's \"g\" and \"o\" lines name them") : list) + "), got \"" +
                      name + "\"");
}

}  // namespace kf
