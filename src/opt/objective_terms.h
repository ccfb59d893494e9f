#pragma once
// Keyframe terms g(x, v) of the objective, each evaluated at one frame with its gradient.
//
// x, v: 3p stacked positions (metres) and velocities (m/s). Every term adds its gradient to gx, gv.
#include <memory>
#include <string>
#include <vector>

#include "core/types.h"
#include "scene/objective_spec.h"

namespace kf {

class ObjectiveTerm {
 public:
  virtual ~ObjectiveTerm() = default;
  virtual std::string name() const = 0;
  virtual int frame() const = 0;
  // Returns g(x, v) and adds dg/dx to gx, dg/dv to gv.
  virtual double eval(const VecX& x, const VecX& v, VecX& gx, VecX& gv) const = 0;
};

// Builds the term a scene's objective entry names, for a system of `particles` particles (each kind's term
// is in its own file, opt/keyframes/<kind>_keyframe.cpp).
std::unique_ptr<ObjectiveTerm> make_objective_term(const ObjectiveSpec& spec, int particles);

}  // namespace kf
