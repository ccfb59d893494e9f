#pragma once
// The reports of keyframe compare: compare.json (every metric) and JUnit XML (one test case per frame).
#include <string>

#include "render/compare/compare_frames.h"

namespace kf::render {

// compare.json: the request's directories and thresholds, counts, and each frame's metrics
// (psnr is null for identical frames) and diff image names.
std::string compare_json(const CompareRequest& request, const CompareResult& result);

// JUnit XML: one <testsuite> named after the reference directory, one <testcase> per frame,
// <failure> with the broken threshold for failing ones.
std::string compare_junit(const CompareRequest& request, const CompareResult& result);

}  // namespace kf::render
