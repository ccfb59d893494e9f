#pragma once
// A keyframe kind in one place. The scene file's struct for the kind (scene/objective_spec.h) and its
// parsing (scene/scene.cpp) stay in the scene layer; everything the later layers do with it is in its own
// file here, opt/keyframes/<kind>_keyframe.cpp: its objective term, its measures (what report.json says
// about how the keyframe was met), its tolerance (whether it was met: the stop rule and the diagnosis judge
// by it) and where it places the particles (the throw fit and the pinned sheet's reach check read that).
// Only its drawing is in render/.
//
// The file defines KeyframeRules<K> and instantiates KeyframeKind<K> (see keyframe_rules.h). The
// functions below visit every kind through KeyframeKind<K>, so a kind without its file stops the build at
// the link, naming KeyframeKind<FooKeyframe>; the drawing's visitors (render/geometry/) name it at compile.
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/trajectory.h"
#include "core/types.h"
#include "opt/objective_terms.h"
#include "scene/scene.h"

namespace kf {

// One keyframe measured in one run: report.json's measures and the judgement against its tolerance.
struct KeyframeMeasure {
  nlohmann::json report = nlohmann::json::object();  // its measures (figure_measures adds "type", "frame")
  bool judged = false;     // false: no tolerance for this kind (velocity keyframes); never a miss
  double miss = 0;         // error / tolerance: <= 1 is met
  std::string error;       // the error in the measure's unit ("12.30 cm", "inside 0.620")
  std::string tolerance;   // "1.20 cm", "inside >= 0.95 and coverage >= 0.9"
  const char* error_phrase = "";  // how the error reads after it in a keyframe's line (" from its target")
  bool from_target = true;  // the error is how far from a target; false: a state reached ("inside 0.620")
};

// The run a keyframe is measured in, and the frame it is measured at (its own, or the last one recorded).
struct KeyframeRun {
  const Scene& scene;
  const Trajectory& t;
  int f = 0;
};

// Where a keyframe puts its particles, as far as a rigid motion of the whole sheet can tell: a target for
// each particle (or one for all of them), one for their centroid, or nothing.
struct KeyframePlacement {
  enum class Kind { kNone, kParticles, kCentroid };
  Kind kind = Kind::kNone;
  std::vector<Vec3> targets;  // kParticles: one per keyframe particle, or one for all; kCentroid: one
};

// What a kind does beyond its scene-file struct; defined in the kind's own file (keyframe_rules.h).
template <class K>
struct KeyframeKind {
  // g(x, v) at the keyframe's frame with its gradient, for a system of `particles` particles.
  static std::unique_ptr<ObjectiveTerm> term(const ObjectiveSpec& s, const K& k, int particles);
  static KeyframeMeasure measure(const KeyframeRun& run, const ObjectiveSpec& s, const K& k);
  static KeyframePlacement placement(const ObjectiveSpec& s, const K& k);
};

// scene.objectives[i] measured in a run (at frame min(frame, last)), in order.
std::vector<KeyframeMeasure> measure_keyframes(const Scene& scene, const Trajectory& t);
KeyframePlacement keyframe_placement(const ObjectiveSpec& s);

}  // namespace kf
