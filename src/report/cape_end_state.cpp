#include "report/cape_end_state.h"

#include <algorithm>
#include <cmath>

namespace kf {

nlohmann::json cape_end_state(const Scene& scene, const Trajectory& run, const Trajectory& uncontrolled) {
  if (!scene.character || !scene.cloth || scene.character->target_run.empty()) return nlohmann::json();
  // The end target: the position and velocity keyframes the character block appended.
  const ObjectiveSpec *pos = nullptr, *vel = nullptr;
  for (const auto& o : scene.objectives) {
    if (o.source != ObjectiveSource::kEndTarget) continue;
    if (std::holds_alternative<PositionKeyframe>(o.kind)) pos = &o;
    if (std::holds_alternative<VelocityKeyframe>(o.kind)) vel = &o;
  }
  if (!pos || !vel) return nlohmann::json();
  const auto& pos_targets = std::get<PositionKeyframe>(pos->kind).targets;
  const auto& vel_targets = std::get<VelocityKeyframe>(vel->kind).targets;
  const double length = scene.cloth->height;
  auto rms = [](const VecX& q, const std::vector<Vec3>& t) {
    double sum = 0;
    for (size_t i = 0; i < t.size(); ++i) sum += (seg(q, int(i)) - t[i]).squaredNorm();
    return std::sqrt(sum / double(t.size()));
  };
  auto of = [&](const Trajectory& t) {
    const int f = std::min(pos->frame, t.frames() - 1);
    const double ex = rms(t.x[f], pos_targets);
    return nlohmann::json{{"rms_position_error", ex},
                          {"rms_position_error_percent", 100.0 * ex / length},
                          {"rms_velocity_error", rms(t.v[std::min(vel->frame, t.frames() - 1)], vel_targets)}};
  };
  return {{"frame", pos->frame}, {"cape_length", length}, {"controlled", of(run)}, {"uncontrolled", of(uncontrolled)}};
}

}  // namespace kf
