#pragma once
// Where a cloth mesh's particles start and what they weigh (cloth.mesh).
#include "scene/cloth_spec.h"

namespace kf {

// Per vertex, the unit area-weighted normal of its faces (a polygon's by Newell's sum; +Y where they cancel).
std::vector<Vec3> mesh_vertex_normals(const ClothMesh& mesh, const VecX& x);

// The mesh's rest positions (3p, metres) with the spec's imperfection along each vertex's normal (the grid's
// draws, one per particle in order, so a flat grid written as a mesh starts where the grid does).
VecX mesh_rest_positions(const ClothSpec& spec);

// Particle masses (p, kg) summing to spec.mass: a face's area shared evenly by its corners (mass_by "area"),
// or spec.mass / p each. Throws InputError naming the file when a vertex's faces have no area.
VecX mesh_masses(const ClothSpec& spec);

}  // namespace kf
