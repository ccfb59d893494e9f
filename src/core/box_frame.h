#pragma once
// The world-from-box rotation of a box or rectangle collider, shared by its contact and its drawing.
#include "core/types.h"

namespace kf {

// The unit u and v axes and u x v as columns.
inline Mat3 box_frame(const Vec3& u, const Vec3& v) {
  Mat3 r;
  r.col(0) = u.normalized();
  r.col(1) = v.normalized();
  r.col(2) = r.col(0).cross(r.col(1));
  return r;
}

}  // namespace kf
