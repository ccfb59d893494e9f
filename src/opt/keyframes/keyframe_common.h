#pragma once
// What several keyframe kinds share: their particles, the sheet's size their tolerances scale with, the
// judgement of a distance, and the term pulling particles' positions or velocities onto targets.
#include <string>
#include <vector>

#include "opt/keyframes/keyframe_kind.h"

namespace kf {

// Particle indices a keyframe applies to: the listed ones, or all.
std::vector<int> keyframe_members(const ObjectiveSpec& s, int particles);

// The mean of x over `ids` (all particles when empty).
Vec3 mean_of(const VecX& x, const std::vector<int>& ids);

// The sheet's width at frame 0 (x0): a grid's first row's length; a mesh's largest extent along an axis.
double sheet_width(const Scene& scene, const VecX& x0);

// A cloth keyframe's distance tolerance: 1 cm or 1 % of the sheet's longer side, whichever is larger.
double cloth_tolerance(const Scene& scene);

std::string format_number(const char* fmt, double a, double b = 0);
std::string centimetres(double metres);

// m judged as a distance `error` (metres) within `tolerance` (metres).
void judge_distance(KeyframeMeasure& m, double error, double tolerance);

// Σ‖q_i − t_i‖² over the keyframe's particles in q (positions or velocities); n: how many.
double target_squared_error(const ObjectiveSpec& o, const std::vector<Vec3>& targets, const VecX& q, int& n);

// ½w Σ‖x_i − t_i‖² (position) or ½w Σ‖v_i − t_i‖² (velocity).
class TargetsTerm : public ObjectiveTerm {
 public:
  TargetsTerm(const ObjectiveSpec& s, const std::vector<Vec3>& targets, int p, bool on_velocity)
      : frame_(s.frame), w_(s.weight), ids_(keyframe_members(s, p)), targets_(targets), on_velocity_(on_velocity) {}
  std::string name() const override { return on_velocity_ ? "velocity" : "position"; }
  int frame() const override { return frame_; }
  double eval(const VecX& x, const VecX& v, VecX& gx, VecX& gv) const override;

 private:
  int frame_;
  double w_;
  std::vector<int> ids_;
  std::vector<Vec3> targets_;
  bool on_velocity_;
};

}  // namespace kf
