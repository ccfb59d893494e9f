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
// Throws InputError when the mesh name does not exist; `where` ("file: /pointer" of the anchors block)
// starts the message, which lists the meshes there are.
std::vector<int> nearest_bind_vertices(const Character& character, const std::vector<Vec3>& targets,
                                       const std::string& mesh = "", const std::string& where = "");

// Bind-pose position of a node (file frame, before the placement): a bone's where the bind pose puts it
// (Character::bind_vertices), any other node's from its rest transforms.
Vec3 node_bind_position(const Character& character, int node);

// The anchor points, file frame: anchors.points, or the bind-pose positions of anchors.nodes (throws
// InputError naming anchors.where and the nodes there are when a name is missing).
std::vector<Vec3> cape_anchor_points(const Character& character, const CapeAnchors& anchors);

// nearest_bind_vertices of cape_anchor_points: one vertex index per anchor.
std::vector<int> cape_anchor_vertices(const Character& character, const CapeAnchors& anchors);

// Posed positions of `vertices` from a posed vertex array x (3n): out = 3 * vertices.size() entries.
// Allocation-free when out already has that size.
void gather_vertices(const VecX& x, const std::vector<int>& vertices, VecX& out);

}  // namespace kf
