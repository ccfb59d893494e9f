#pragma once
// The metric a projection onto the keyframes takes its minimum-norm step in (opt/keyframe_projection.h), per
// control kind. Plain per-particle controls (initial velocities, or one force per particle per step or frame)
// get a smooth one over the sheet: minimum-norm in plain values, a step moves the keyframed particles alone
// (their own controls move them most) and the springs then pull them back, so the linear model fails. The
// lattice and rigid bases are smooth already and keep the plain metric.
#include "core/types.h"
#include "opt/controls.h"

namespace kf {

class ProjectionMetric {
 public:
  // x0: the sheet's initial positions (3p); `planar`: the system controls x and z only (controls.h);
  // `smooth` false gives the plain metric for every kind.
  ProjectionMetric(const Controls& controls, const VecX& x0, bool planar, bool smooth);
  // Each row of j (one column per control variable) times the metric's kernel: J K, what the step −K Jᵀ y
  // and the linearised change J K Jᵀ y are made of.
  Eigen::MatrixXd times_kernel(const Eigen::MatrixXd& j) const;
  bool smooth() const { return kernel_.size() > 0; }

 private:
  Eigen::MatrixXd kernel_;  // p x p over the particles; empty: the identity
  int components_ = 3;      // controlled components per particle
  int block_ = 0;           // variables per block (a step's or frame's forces, or the initial velocities)
};

}  // namespace kf
