#pragma once
// The springs of a cloth mesh (cloth.mesh), the grid's kinds found from its faces, so that a grid written as
// a quad mesh gets the grid's springs, in the grid's order:
//   type 1 (damped): each face edge (stretch stiffness), then both diagonals of each quad (shear);
//   type 2: bending across each edge two faces share: for each end e of the edge, a spring between e's other
//   neighbour in one face and in the other (a triangle pair: its two opposite corners; a grid: particles two
//   apart in a row or column).
// A pair of particles gets one spring, of the first kind that joins it. Each kind is sorted by (a, b), a < b.
#include "scene/cloth_spec.h"
#include "sim/cloth/cloth_springs.h"

namespace kf {

// Rest lengths from x0 (3p, metres). Throws InputError naming the mesh file when two joined vertices coincide.
ClothSprings make_mesh_springs(const ClothSpec& spec, const ClothMesh& mesh, const VecX& x0);

}  // namespace kf
