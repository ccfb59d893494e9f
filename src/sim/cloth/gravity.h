#pragma once
// Gravity: f_i = m_i g. Constant, so its Jacobians are zero.
#include "core/types.h"

namespace kf {

// m: kg; g: m/s^2. Force in N.
inline Vec3 gravity_force(double m, const Vec3& g) { return m * g; }

}  // namespace kf
