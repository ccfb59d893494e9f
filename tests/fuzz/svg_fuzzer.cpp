// libFuzzer target for SVG shape files: any bytes are either an SVG document whose <path> elements flatten
// to closed loops of finite points, or a std::runtime_error (an SvgPathError for path data); a crash, a
// leak, a hang or a loop with a non-finite point is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "scene/svg_path.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<kf::SvgPathElement> paths;
  try {
    paths = kf::svg_document_paths(text);
  } catch (const std::runtime_error&) {
    return 0;
  }
  // The same bytes' paths at a coarse and a fine tolerance (a shape scaled up flattens to more points).
  for (const double tolerance : {1.0, 1e-6})
    for (const kf::SvgPathElement& p : paths) {
      try {
        for (const kf::SvgLoop& loop : kf::svg_path_loops(p.d, tolerance, 20'000))
          for (const kf::Vec2& q : loop.points)
            if (!std::isfinite(q.x()) || !std::isfinite(q.y())) __builtin_trap();
      } catch (const kf::SvgPathError& e) {
        if (e.position > p.d.size()) __builtin_trap();  // the position must be inside the path or its end
      }
    }
  return 0;
}
