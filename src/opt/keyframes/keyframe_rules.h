#pragma once
// Included by each kind's file only (opt/keyframes/<kind>_keyframe.cpp), which writes
//
//   template <> struct KeyframeRules<FooKeyframe> {
//     static std::unique_ptr<ObjectiveTerm> term(const ObjectiveSpec&, const FooKeyframe&, int particles);
//     static KeyframeMeasure measure(const KeyframeRun&, const ObjectiveSpec&, const FooKeyframe&);
//     static KeyframePlacement placement(const ObjectiveSpec&, const FooKeyframe&);
//   };
//   template struct KeyframeKind<FooKeyframe>;
//
// The explicit instantiation gives KeyframeKind<FooKeyframe>'s functions their one definition, so the
// visitors (keyframe_kinds.cpp) need no list of the kinds' files.
#include "opt/keyframes/keyframe_kind.h"

namespace kf {

template <class K>
struct KeyframeRules;

template <class K>
std::unique_ptr<ObjectiveTerm> KeyframeKind<K>::term(const ObjectiveSpec& s, const K& k, int particles) {
  return KeyframeRules<K>::term(s, k, particles);
}
template <class K>
KeyframeMeasure KeyframeKind<K>::measure(const KeyframeRun& run, const ObjectiveSpec& s, const K& k) {
  return KeyframeRules<K>::measure(run, s, k);
}
template <class K>
KeyframePlacement KeyframeKind<K>::placement(const ObjectiveSpec& s, const K& k) {
  return KeyframeRules<K>::placement(s, k);
}

}  // namespace kf
