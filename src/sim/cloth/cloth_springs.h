#pragma once
// The cloth's springs (Choi & Ko): type 1 joins grid neighbours (structural: stretch stiffness) and
// diagonal neighbours (shear), type 2 particles two apart in a row or column (bending). Type 1 comes first
// in the list, so the damped springs are [0, damped).
#include <vector>

#include "core/types.h"
#include "scene/cloth_spec.h"
#include "sim/cloth/buckling_spring.h"

namespace kf {

struct ClothSprings {
  std::vector<BucklingSpring> list;
  int damped = 0;  // list[0 .. damped) are type 1 (structural, then shear)

  // Per particle i, the springs it ends, in the fixed order each row gathers them:
  // incident[incident_start[i] .. incident_start[i + 1]).
  struct Incident {
    int spring;  // index into list
    int sign;    // +1 when i is the spring's `a` end, -1 when it is `b`
    int slot;    // block (i, other end) of the step's matrix (set by the assembly)
  };
  std::vector<int> incident_start;
  std::vector<Incident> incident;
};

// The springs of the spec's nx x ny grid, or of its mesh (mesh_springs.h), with rest lengths from x0 (3p,
// metres), the incidence with slots unset (-1).
ClothSprings make_cloth_springs(const ClothSpec& spec, const VecX& x0);

// A spring from a to b of stiffness k in tension, rest length from x0, the spec's Choi-Ko response.
BucklingSpring make_buckling_spring(const ClothSpec& spec, const VecX& x0, int a, int b, double k);
// Fills out.incident_start and out.incident from out.list for p particles.
void set_incidence(ClothSprings& out, int p);

}  // namespace kf
