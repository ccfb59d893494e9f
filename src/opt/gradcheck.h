#pragma once
// The adjoint gradient against central finite differences on a random sample of control coordinates.
#include <nlohmann/json.hpp>

#include "opt/problem.h"

namespace kf {

struct GradcheckResult {
  int checked = 0;             // coordinates compared
  double max_rel_error = 0;    // max |adjoint − fd| / max(|fd|, floor) over the sample
  double cosine = 0;           // between the sampled adjoint and finite-difference vectors
  double rel_error_norm = 0;   // ‖adjoint − fd‖ / ‖fd‖ over the sample
  double floor = 0;            // 1e-3 × the largest sampled |fd|: smaller components are round-off
  double grad_norm = 0;        // ‖dφ/dz‖ over all coordinates
  double phi = 0;
  double eps = 0;
  nlohmann::json to_json() const;
};

// Checks at z (size problem.size()) `samples` coordinates chosen with `seed`, preferring coordinates whose
// adjoint gradient is not negligible so the check cannot pass on zeros. eps (the larger of the two
// Richardson steps) is relative to max(1, |z_i|); 1e-2 suits φ of any size for smooth systems.
GradcheckResult gradcheck(Problem& problem, const VecX& z, int samples, double eps, unsigned seed);

}  // namespace kf
