#pragma once
// The keyframe that stands for a scene in a bench table: the judged one with the largest miss after the
// optimisation, or null when the report judges none.
#include <nlohmann/json.hpp>

namespace kf {

inline const nlohmann::json* worst_judged_keyframe(const nlohmann::json& report) {
  const nlohmann::json* worst = nullptr;
  for (const auto& k : report.at("keyframe_errors"))
    if (k.at("judged").get<bool>() && (!worst || k.at("miss_after").get<double>() > worst->at("miss_after").get<double>()))
      worst = &k;
  return worst;
}

}  // namespace kf
