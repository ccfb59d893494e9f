#include "report/figure_measures.h"

#include "core/check.h"
#include "core/overloaded.h"
#include "report/collider_measures.h"

namespace kf {

nlohmann::json figure_measures(const Scene& scene, const Trajectory& t) {
  return figure_measures(scene, t, measure_keyframes(scene, t));
}

nlohmann::json figure_measures(const Scene& scene, const Trajectory& t, const std::vector<KeyframeMeasure>& keyframes) {
  CHECK_EQ(keyframes.size(), scene.objectives.size());
  nlohmann::json out = nlohmann::json::array();
  for (size_t k = 0; k < keyframes.size(); ++k) {
    nlohmann::json m = keyframes[k].report;
    m["type"] = type_name(scene.objectives[k]);
    m["frame"] = scene.objectives[k].frame;
    out.push_back(m);
  }
  // Then the system's own measures.
  visit_system(scene, Overloaded{
                          [](const FlockSpec&) {},
                          [&](const ClothSpec& cloth) { add_cloth_measures(cloth, t, out); },
                      });
  return out;
}

}  // namespace kf
