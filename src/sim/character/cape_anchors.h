#pragma once
// Where a cape hangs from the character: skinned vertices on the shoulders and upper back whose posed
// positions the cape's pinned particles follow.
#include <string>
#include <vector>

#include "sim/character/character.h"

namespace kf {

// Target points in the file frame of BCN_Epileptic.X (metres, Y up, facing +Z, so the back is -Z),
// ordered by +x (the character's right side first):
//   (-0.18, 0.47, -0.22) right shoulder top, behind the joint
//   (-0.09, 0.44, -0.265) right upper back
//   ( 0.00, 0.50, -0.24) centre, at the base of the neck
//   ( 0.09, 0.44, -0.265) left upper back
//   ( 0.18, 0.47, -0.22) left shoulder top
// The pelvis root is at y = 0.038 and the neck joint at y = 0.55, so they sit about 8 cm below the neck.
std::vector<Vec3> cape_anchor_targets();

// For each target (file frame; the character's placement is applied to it), the index of the nearest
// bind-pose vertex among the vertices of the mesh named `mesh` ("" = every mesh).
// Throws InputError when the mesh name does not exist.
std::vector<int> nearest_bind_vertices(const Character& character, const std::vector<Vec3>& targets,
                                       const std::string& mesh = "");

// nearest_bind_vertices(character, cape_anchor_targets(), "Torso"): 5 vertex indices, ordered by +x.
std::vector<int> cape_anchor_vertices(const Character& character);

// Posed positions of `vertices` from a posed vertex array x (3n): out = 3 * vertices.size() entries.
// Allocation-free when out already has that size.
void gather_vertices(const VecX& x, const std::vector<int>& vertices, VecX& out);

}  // namespace kf
