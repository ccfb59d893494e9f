#include "sim/character/cape_anchors.h"

#include <algorithm>
#include <limits>

#include "core/error.h"

namespace kf {

std::vector<int> nearest_bind_vertices(const Character& character, const std::vector<Vec3>& targets,
                                       const std::string& mesh) {
  int begin = 0, end = character.vertex_count();
  if (!mesh.empty()) {
    const auto& names = character.mesh_names();
    const auto it = std::find(names.begin(), names.end(), mesh);
    if (it == names.end()) throw InputError("character has no mesh named '" + mesh + "'");
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

std::vector<int> cape_anchor_vertices(const Character& character, const CapeAnchors& anchors) {
  return nearest_bind_vertices(character, anchors.points, anchors.mesh);
}

void gather_vertices(const VecX& x, const std::vector<int>& vertices, VecX& out) {
  if (out.size() != 3 * static_cast<Eigen::Index>(vertices.size())) out.resize(3 * vertices.size());
  for (size_t i = 0; i < vertices.size(); ++i) out.segment<3>(3 * i) = seg(x, vertices[i]);
}

}  // namespace kf
