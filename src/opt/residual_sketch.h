#pragma once
// Fewer rows for a Gauss–Newton step on many residuals. A keyframe that places a whole sheet has three
// residuals per particle, and its Jacobian takes one adjoint pass per row; the step instead works on
// orthonormal combinations of them: a keyframe on a few particles keeps its own rows, one on many gets its
// displacement's smooth moments over the sheet's rest positions (the mean, the tilts and the bends, per axis),
// and the current residual vector itself is always one of the combinations, so a step that meets the
// combinations lowers ‖r‖ to first order (what is outside them is zero at the point the Jacobian is formed).
#include <vector>

#include "core/types.h"
#include "opt/keyframe_residuals.h"

namespace kf {

// Keyframes on more particles than this are sketched.
constexpr int kDenseKeyframeParticles = 8;

// Whether any keyframe in `placed` is sketched.
bool sketched(const std::vector<PlacedKeyframe>& placed);

// The combinations as orthonormal rows (at most residual_count(placed) of them, each residual_count(placed)
// long) at residuals r; x0 the sheet's rest positions (3p). The identity when nothing is sketched.
Eigen::MatrixXd residual_sketch(const std::vector<PlacedKeyframe>& placed, const VecX& x0, const VecX& r);

}  // namespace kf
