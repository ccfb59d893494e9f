#pragma once
// A control kind (ControlKind, scene/objective_spec.h) is two axes. Its timing: the initial velocities, or
// forces over time (one per step, or one per frame held over its substeps). Its basis, what one block of
// variables sets: a value per particle, the nodes of a 3 x 3 lattice laid over the sheet (interpolated to
// the particles), or a rigid motion of the whole body (6 variables). ControlKind names the pairs a scene can
// ask for (the evaluation tape stores its number); code that behaves differently asks for the axes.
#include "scene/objective_spec.h"

namespace kf {

enum class ControlTiming { kInitial, kPerStep, kPerFrame };
enum class ControlBasis { kPerParticle, kLattice, kRigid };

constexpr ControlTiming control_timing(ControlKind k) {
  switch (k) {
    case ControlKind::kPerStep: return ControlTiming::kPerStep;
    case ControlKind::kPerFrame:
    case ControlKind::kPerFrameLattice: return ControlTiming::kPerFrame;
    case ControlKind::kInitialVelocity:
    case ControlKind::kInitialRigidVelocity:
    case ControlKind::kInitialLatticeVelocity: return ControlTiming::kInitial;
  }
  return ControlTiming::kPerStep;
}

constexpr ControlBasis control_basis(ControlKind k) {
  switch (k) {
    case ControlKind::kPerStep:
    case ControlKind::kPerFrame:
    case ControlKind::kInitialVelocity: return ControlBasis::kPerParticle;
    case ControlKind::kPerFrameLattice:
    case ControlKind::kInitialLatticeVelocity: return ControlBasis::kLattice;
    case ControlKind::kInitialRigidVelocity: return ControlBasis::kRigid;
  }
  return ControlBasis::kPerParticle;
}

}  // namespace kf
