#include "sim/character/cape_anchors.h"

#include <algorithm>
#include <limits>

#include "core/error.h"

namespace kf {
namespace {

// 'a', 'b', 'c' (at most `most` of them, then how many more).
std::string quoted_list(const std::vector<std::string>& names, size_t most = 40) {
  std::string out;
  for (size_t i = 0; i < names.size() && i < most; ++i) out += (i ? ", '" : "'") + names[i] + "'";
  if (names.size() > most) out += " and " + std::to_string(names.size() - most) + " more";
  return out.empty() ? "none" : out;
}

std::string prefix(const std::string& where, const std::string& key) {
  return where.empty() ? "" : where + "/" + key + ": ";
}

}  // namespace

std::vector<int> nearest_bind_vertices(const Character& character, const std::vector<Vec3>& targets,
                                       const std::string& mesh, const std::string& where) {
  int begin = 0, end = character.vertex_count();
  if (!mesh.empty()) {
    const auto& names = character.mesh_names();
    const auto it = std::find(names.begin(), names.end(), mesh);
    if (it == names.end())
      throw InputError(prefix(where, "mesh") + "no mesh named '" + mesh + "' in " + character.file() +
                       " (its meshes: " + quoted_list(names) + "; \"\" for all of them)");
    const auto m = static_cast<size_t>(it - names.begin());
    begin = character.mesh_vertex_begin()[m];
    end = character.mesh_vertex_begin()[m + 1];
  }
  const VecX& x = character.bind_vertices();
  std::vector<int> nearest;
  for (const Vec3& target : targets) {
    const Vec3 p = character.placement() * target;
    int best = -1;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (int v = begin; v < end; ++v) {
      const double d2 = (seg(x, v) - p).squaredNorm();
      if (d2 < best_d2) best_d2 = d2, best = v;
    }
    nearest.push_back(best);
  }
  return nearest;
}

Vec3 node_bind_position(const Character& character, int node) {
  for (const CharacterBone& b : character.bones())
    if (b.node == node) return b.bind.translation();
  Affine world = Affine::Identity();
  for (int n = node; n >= 0; n = character.nodes()[size_t(n)].parent) world = character.nodes()[size_t(n)].rest_local * world;
  return world.translation();
}

std::vector<Vec3> cape_anchor_points(const Character& character, const CapeAnchors& anchors) {
  if (anchors.nodes.empty()) return anchors.points;
  std::vector<Vec3> points;
  for (size_t i = 0; i < anchors.nodes.size(); ++i) {
    const int node = character.node_index(anchors.nodes[i]);
    if (node < 0) {
      // Bones first: they are what a cape hangs from.
      std::vector<std::string> bones, others;
      for (const CharacterNode& n : character.nodes()) {
        const bool bone = std::any_of(character.bones().begin(), character.bones().end(),
                                      [&](const CharacterBone& b) { return character.nodes()[size_t(b.node)].name == n.name; });
        (bone ? bones : others).push_back(n.name);
      }
      throw InputError(prefix(anchors.where, "nodes/" + std::to_string(i)) + "no node named '" + anchors.nodes[i] +
                       "' in " + character.file() + " (its bones: " + quoted_list(bones) + "; other nodes: " +
                       quoted_list(others, 10) + ")");
    }
    points.push_back(node_bind_position(character, node));
  }
  return points;
}

std::vector<int> cape_anchor_vertices(const Character& character, const CapeAnchors& anchors) {
  return nearest_bind_vertices(character, cape_anchor_points(character, anchors), anchors.mesh, anchors.where);
}

void gather_vertices(const VecX& x, const std::vector<int>& vertices, VecX& out) {
  if (out.size() != 3 * static_cast<Eigen::Index>(vertices.size())) out.resize(3 * vertices.size());
  for (size_t i = 0; i < vertices.size(); ++i) out.segment<3>(3 * i) = seg(x, vertices[i]);
}

}  // namespace kf
