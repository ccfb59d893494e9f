#pragma once
// SVG path data ("M 0 0 L 10 0 ... Z", the `d` attribute of an SVG <path>) as closed polygons, and the `d`
// attributes of the <path> elements of an SVG file. Every command of SVG 1.1's path grammar is read: M L H V
// C S Q T A Z, absolute (upper case) and relative (lower case), with implicit repetition (extra pairs after
// M are line-tos). Curves and arcs are flattened so that every point of the curve lies within `tolerance`
// of the polygon.
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/types.h"

namespace kf {

// A problem in path data at `position`: the 0-based index of the offending character (d.size() for "the
// path ended early").
struct SvgPathError : std::runtime_error {
  SvgPathError(size_t at, const std::string& what) : std::runtime_error(what), position(at) {}
  size_t position;
};

// One subpath as a closed polygon (the last point joins the first; an open subpath is closed as SVG fills
// it), in the path's own units (x right, y down), with `start`: the index in `d` of the command that began it.
struct SvgLoop {
  std::vector<Vec2> points;
  size_t start = 0;
};

// The subpaths of path data `d`, curves flattened to `tolerance` (path units, > 0). Consecutive repeated
// points and a closing point equal to the first are dropped. Throws SvgPathError for bad syntax, a subpath
// of fewer than 3 distinct points or enclosing no area, or more than `max_points` points in all.
std::vector<SvgLoop> svg_path_loops(std::string_view d, double tolerance, size_t max_points = 100'000);

// The `d` attribute of one <path> element of an SVG document, and the line (1-based) where the element starts.
struct SvgPathElement {
  std::string d;
  int line = 0;
};

// The <path> elements of an SVG document (read by pugixml), in document order. Throws std::runtime_error
// (with the line) for XML that is not well formed; for what an XML reader and a person may read differently:
// a document type declaration (its entities can hold elements), an attribute given twice, an entity in d;
// for what this reader does not apply: a transform (attribute or CSS property in "style") anywhere, a <path>
// without "d"; and when there is no <path> at all. Other elements (rect, circle, text) are not read:
// convert them to paths first.
std::vector<SvgPathElement> svg_document_paths(const std::string& text);

}  // namespace kf
