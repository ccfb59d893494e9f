#pragma once
// The generated suite's classes as test parameters: those without and those with a character are
// instantiated apart (Embree's queries run untrapped: tests/test_main.cpp).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "bench/bench_reachable.h"

namespace kf::test {

inline std::vector<std::string> reachable_classes_with_character(bool character) {
  std::vector<std::string> v;
  for (const std::string& c : reachable_classes())
    if (reachable_class_on_character(c) == character) v.push_back(c);
  return v;
}

// A class name as a test name ("drop-collider" → "drop_collider").
inline std::string class_test_name(const testing::TestParamInfo<std::string>& info) {
  std::string s = info.param;
  for (char& c : s)
    if (c == '-') c = '_';
  return s;
}

}  // namespace kf::test
