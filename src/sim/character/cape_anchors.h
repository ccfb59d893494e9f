#pragma once
// Where a cape hangs from the character: skinned vertices on the shoulders and upper back whose posed
// positions the cape's pinned particles follow.
#include <string>
#include <vector>

#include "scene/character_spec.h"
#include "sim/character/character.h"

namespace kf {

// For each target (file frame; the character's placement is applied to it), the index of the nearest
// bind-pose vertex among the vertices of the mesh named `mesh` ("" = every mesh).
// Throws InputError when the mesh name does not exist.
std::vector<int> nearest_bind_vertices(const Character& character, const std::vector<Vec3>& targets,
                                       const std::string& mesh = "");

// nearest_bind_vertices(character, anchors.points, anchors.mesh): one vertex index per anchor point.
std::vector<int> cape_anchor_vertices(const Character& character, const CapeAnchors& anchors);

// Posed positions of `vertices` from a posed vertex array x (3n): out = 3 * vertices.size() entries.
// Allocation-free when out already has that size.
void gather_vertices(const VecX& x, const std::vector<int>& vertices, VecX& out);

}  // namespace kf
