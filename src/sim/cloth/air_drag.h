#pragma once
// Linear air drag proportional to mass, so a finer cloth falls the same way: f_i = -c m_i v_i.
#include "core/types.h"

namespace kf {

// c: 1/s; m: kg; v: m/s. Force in N.
inline Vec3 air_drag_force(double c, double m, const Vec3& v) { return -c * m * v; }
// d f_i / d v_i = -c m I (N s/m); the force does not depend on x.
inline Mat3 air_drag_jacobian_v(double c, double m) { return -c * m * Mat3::Identity(); }

}  // namespace kf
