#pragma once
// Where pinned particles are at each step. The default keeps them at their initial positions; a scripted
// track (a cape's shoulders following a character) implements the same interface.
#include "core/types.h"

namespace kf {

class PinTrack {
 public:
  virtual ~PinTrack() = default;
  // Position (m) and velocity (m/s) of pinned particle `particle` at step n (n = 0 .. steps), given its
  // initial position x0. The step moves a pinned particle from wherever it is to position(n+1) exactly.
  virtual void state(int n, int particle, const Vec3& x0, Vec3& position, Vec3& velocity) const = 0;
};

class StaticPins final : public PinTrack {
 public:
  void state(int, int, const Vec3& x0, Vec3& position, Vec3& velocity) const override {
    position = x0;
    velocity.setZero();
  }
};

}  // namespace kf
