#include "opt/keyframe_weights.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace kf {

std::vector<double> raised_weight_scales(const std::vector<double>& scales, const std::vector<bool>& unmet,
                                         const KeyframeWeightRule& rule, int round) {
  const double factor = std::pow(rule.factor, round);
  std::vector<double> out(unmet.size(), 1.0);
  for (size_t k = 0; k < unmet.size(); ++k) {
    if (k < scales.size()) out[k] = scales[k];
    if (unmet[k]) out[k] *= factor;
  }
  return out;
}

bool any_unmet(const std::vector<bool>& unmet) { return std::find(unmet.begin(), unmet.end(), true) != unmet.end(); }

std::string describe_raise(const std::vector<std::string>& names, const std::vector<double>& scales,
                           const std::vector<bool>& unmet) {
  std::ostringstream os;
  os << "keyframes outside their tolerance: weight of ";
  bool first = true;
  for (size_t k = 0; k < unmet.size() && k < scales.size(); ++k) {
    if (!unmet[k]) continue;
    os << (first ? "" : ", ") << (k < names.size() ? names[k] : "keyframe " + std::to_string(k)) << " now " << scales[k]
       << " times the scene's";
    first = false;
  }
  os << "; going on from the best point";
  return os.str();
}

}  // namespace kf
