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

// Builds the term a scene's objective entry names, for a system of `particles` particles.
std::unique_ptr<ObjectiveTerm> make_objective_term(const ObjectiveSpec& spec, int particles);

// Geometry shared by terms and the figures' success measures.
// Closest point of the closed polygon region (x, z) to q; returns q itself when q is inside.
Vec2 closest_point_in_polygon(const std::vector<Vec2>& polygon, const Vec2& q, bool* inside = nullptr);
// Closest point of the polygon's boundary (its edges) to q, inside or out.
Vec2 closest_point_on_boundary(const std::vector<Vec2>& polygon, const Vec2& q);
bool polygon_contains(const std::vector<Vec2>& polygon, const Vec2& q);
// The points of a square grid of `spacing` (cell centres, centred in the polygon's bounding box) inside the polygon: where
// a shape keyframe asks for an agent nearby. Throws InputError past 100,000 points.
std::vector<Vec2> region_samples(const std::vector<Vec2>& polygon, double spacing);

}  // namespace kf
