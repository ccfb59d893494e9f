// SVG path data as closed polygons: every command absolute and relative, implicit repetition, the number
// syntax's run-together forms, curves and arcs flattened within the tolerance, several subpaths, and bad
// paths named by their character. Then the <path> elements of an SVG document.
#include "scene/svg_path.h"

#include <gtest/gtest.h>

#include <cmath>

namespace kf {
namespace {

std::vector<Vec2> only_loop(const std::string& d, double tol = 0.01) {
  const std::vector<SvgLoop> loops = svg_path_loops(d, tol);
  EXPECT_EQ(loops.size(), 1u) << d;
  return loops.empty() ? std::vector<Vec2>{} : loops[0].points;
}

void expect_points(const std::vector<Vec2>& got, const std::vector<Vec2>& want, const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (size_t k = 0; k < got.size(); ++k) EXPECT_LT((got[k] - want[k]).norm(), 1e-12) << what << " point " << k;
}

std::string error_of(const std::string& d, double tol = 0.01, size_t max_points = 100'000) {
  try {
    svg_path_loops(d, tol, max_points);
  } catch (const SvgPathError& e) {
    return e.what();
  }
  return "accepted";
}

double segment_distance(const Vec2& q, const Vec2& a, const Vec2& b) {
  const Vec2 e = b - a;
  const double t = std::clamp((q - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
  return (q - (a + t * e)).norm();
}

// Farthest that a densely sampled curve strays from the polyline `poly` (open: its consecutive points).
template <class Curve>
double farthest_from(const std::vector<Vec2>& poly, Curve curve) {
  double worst = 0;
  for (int s = 0; s <= 4000; ++s) {
    const Vec2 q = curve(s / 4000.0);
    double best = INFINITY;
    for (size_t k = 0; k + 1 < poly.size(); ++k) best = std::min(best, segment_distance(q, poly[k], poly[k + 1]));
    worst = std::max(worst, best);
  }
  return worst;
}

TEST(SvgPath, LinesAbsoluteAndRelative) {
  const std::vector<Vec2> tri = {{1, 2}, {5, 2}, {5, 6}};
  expect_points(only_loop("M 1 2 L 5 2 L 5 6 Z"), tri, "M L Z");
  expect_points(only_loop("m 1 2 l 4 0 l 0 4 z"), tri, "m l z (a first m is absolute)");
  expect_points(only_loop("M1 2 5 2 5 6"), tri, "pairs after M are line-tos; an open subpath is closed");
  expect_points(only_loop("m1 2 4 0 0 4"), tri, "pairs after m are relative line-tos");
  const std::vector<Vec2> rect = {{0, 0}, {4, 0}, {4, 3}, {0, 3}};
  expect_points(only_loop("M 0 0 H 4 V 3 H 0 Z"), rect, "H V");
  expect_points(only_loop("M0 0h4v3h-4z"), rect, "h v");
  expect_points(only_loop("M 0 0 H 2 3 4 V 1 3 L 0 3 0 0"), {{0, 0}, {2, 0}, {3, 0}, {4, 0}, {4, 1}, {4, 3}, {0, 3}},
                "repeated H and V; the closing point dropped");
  // Numbers run together: a sign or a second '.' starts the next number; exponents; commas.
  expect_points(only_loop("M0,0L4-0L4,3.5e0L.5.5z"), {{0, 0}, {4, 0}, {4, 3.5}, {0.5, 0.5}}, "compact numbers");
  expect_points(only_loop("M+1E0 2e+0 L 50e-1 2 L 5 6"), tri, "exponents and a plus sign");
}

TEST(SvgPath, CubicsWithinTheToleranceAndSmoothContinuations) {
  const Vec2 p0(0, 0), p1(0, 10), p2(10, 10), p3(10, 0);
  auto bezier = [&](double t) {
    const double s = 1 - t;
    return Vec2(s * s * s * p0 + 3 * s * s * t * p1 + 3 * s * t * t * p2 + t * t * t * p3);
  };
  for (double tol : {0.1, 0.01, 0.001}) {
    std::vector<Vec2> poly = only_loop("M 0 0 C 0 10 10 10 10 0 Z", tol);
    ASSERT_GT(poly.size(), 4u);
    EXPECT_EQ(poly.back(), p3);  // the end point exactly
    EXPECT_LE(farthest_from(poly, bezier), tol) << "tolerance " << tol;
    EXPECT_GT(farthest_from(poly, bezier), 0.1 * tol) << "no more points than needed, tolerance " << tol;
    for (const Vec2& q : poly) {  // every point lies on the curve (dyadic de Casteljau points)
      double best = INFINITY;
      for (int s = 0; s <= 1 << 14; ++s) best = std::min(best, (bezier(s / double(1 << 14)) - q).norm());
      EXPECT_LT(best, 1e-9) << q.transpose();
    }
  }
  expect_points(only_loop("m 0 0 c 0 10 10 10 10 0 z"), only_loop("M 0 0 C 0 10 10 10 10 0 Z"), "c");
  // S reflects the previous cubic's second control point about the current point; after a non-curve, the
  // first control point is the current point.
  expect_points(only_loop("M0 0 C 0 1 1 1 1 0 S 2 -1 2 0 Z"), only_loop("M0 0 C 0 1 1 1 1 0 C 1 -1 2 -1 2 0 Z"), "S");  // a figure eight
  expect_points(only_loop("M0 0 C 0 1 1 1 1 0 s 1 -1 1 0 Z"), only_loop("M0 0 C 0 1 1 1 1 0 C 1 -1 2 -1 2 0 Z"), "s");
  expect_points(only_loop("M0 0 L 0 1 S 2 2 2 0 Z"), only_loop("M0 0 L 0 1 C 0 1 2 2 2 0 Z"), "S after L");
}

TEST(SvgPath, QuadraticsWithinTheToleranceAndSmoothContinuations) {
  auto quad = [](double t) {
    const double s = 1 - t;
    return Vec2(2 * s * t * Vec2(2, 8) + t * t * Vec2(4, 0));
  };
  for (double tol : {0.05, 0.005}) {
    const std::vector<Vec2> poly = only_loop("M 0 0 Q 2 8 4 0 Z", tol);
    ASSERT_GT(poly.size(), 3u);
    EXPECT_LE(farthest_from(poly, quad), tol);
    EXPECT_GT(farthest_from(poly, quad), 0.1 * tol);
  }
  expect_points(only_loop("m 0 0 q 2 8 4 0 z"), only_loop("M 0 0 Q 2 8 4 0 Z"), "q");
  expect_points(only_loop("M0 0 Q 2 8 4 0 T 8 0 Z"), only_loop("M0 0 Q 2 8 4 0 Q 6 -8 8 0 Z"), "T");
  expect_points(only_loop("M0 0 Q 2 8 4 0 t 4 0 Z"), only_loop("M0 0 Q 2 8 4 0 Q 6 -8 8 0 Z"), "t");
}

TEST(SvgPath, ArcsOnTheirEllipseWithinTheTolerance) {
  // From (-1, 0) to (1, 0) on the unit circle; sweep 1 turns through increasing angles, in SVG's y-down
  // frame through (0, -1).
  const std::vector<Vec2> half = only_loop("M -1 0 A 1 1 0 0 1 1 0 Z", 0.001);
  ASSERT_GT(half.size(), 10u);
  EXPECT_EQ(half.back(), Vec2(1, 0));
  for (const Vec2& q : half) {
    EXPECT_NEAR(q.norm(), 1.0, 1e-12);
    EXPECT_LE(q.y(), 1e-12);
  }
  EXPECT_LE(farthest_from(half, [](double t) { return Vec2(-std::cos(M_PI * t), -std::sin(M_PI * t)); }), 0.001);
  const std::vector<Vec2> other = only_loop("M -1 0 A 1 1 0 0 0 1 0 Z", 0.001);  // sweep 0: through (0, 1)
  for (const Vec2& q : other) EXPECT_GE(q.y(), -1e-12);
  expect_points(only_loop("m -1 0 a 1 1 0 0 1 2 0 z", 0.001), half, "a");
  // Radii too small for the end points are scaled up until they fit: a half circle of radius 1 about (1, 0).
  for (const Vec2& q : only_loop("M 0 0 A 0.1 0.1 0 0 1 2 0 Z")) EXPECT_NEAR((q - Vec2(1, 0)).norm(), 1.0, 1e-12);
  // The large-arc flag: three quarters of the circle of radius 1 about (0, 1), from (0, 0) through
  // decreasing angles (sweep 0) by (-1, 1) and (0, 2) to (1, 1).
  const std::vector<Vec2> large = only_loop("M 0 0 A 1 1 0 1 0 1 1 Z", 0.001);
  double left = 0, low = 0;
  for (const Vec2& q : large) {
    EXPECT_NEAR((q - Vec2(0, 1)).norm(), 1.0, 1e-12) << q.transpose();
    left = std::min(left, q.x()), low = std::max(low, q.y());
  }
  EXPECT_LT(left, -0.999);
  EXPECT_GT(low, 1.999);
  // A rotated ellipse (radii 2 and 1, x axis at 30 degrees) through its end points.
  const std::vector<Vec2> tilted = only_loop("M 0 0 A 2 1 30 0 1 3 1 L 3 3 Z", 0.001);
  EXPECT_EQ(tilted[tilted.size() - 2], Vec2(3, 1));
  // Zero radii draw a line; an arc to its own start is left out.
  expect_points(only_loop("M 0 0 A 0 1 0 0 1 4 0 L 4 3 A 1 1 0 0 1 4 3 Z"), {{0, 0}, {4, 0}, {4, 3}}, "degenerate arcs");
}

TEST(SvgPath, SubpathsAndDrawingOnAfterClose) {
  const std::vector<SvgLoop> loops = svg_path_loops("M0 0 H10 V10 H0 Z M2 2 H4 V4 H2 Z", 0.01);
  ASSERT_EQ(loops.size(), 2u);
  EXPECT_EQ(loops[0].start, 0u);
  EXPECT_EQ(loops[1].start, 18u);  // the second M
  expect_points(loops[1].points, {{2, 2}, {4, 2}, {4, 4}, {2, 4}}, "second subpath");
  // After Z the current point is the subpath's start: a relative m and a drawing command both start there.
  const std::vector<SvgLoop> rel = svg_path_loops("M 1 1 h 4 v 4 z m 1 1 h 2 v 2 z", 0.01);
  ASSERT_EQ(rel.size(), 2u);
  expect_points(rel[1].points, {{2, 2}, {4, 2}, {4, 4}}, "relative m after z");
  const std::vector<SvgLoop> on = svg_path_loops("M 0 0 L 4 0 L 4 4 Z L 0 4 L -4 4 Z", 0.01);
  ASSERT_EQ(on.size(), 2u);
  expect_points(on[1].points, {{0, 0}, {0, 4}, {-4, 4}}, "drawing on after Z");
  EXPECT_EQ(on[1].start, 20u);  // the L after Z
}

TEST(SvgPath, BadPathsNameTheCharacter) {
  EXPECT_EQ(error_of(""), "end of the path (character 1): expected M or m to begin the path, got an empty path");
  EXPECT_EQ(error_of("L 0 0 1 1"), "character 1 ('L'): expected M or m to begin the path");
  EXPECT_EQ(error_of("0 0"), "character 1 ('0'): expected M or m to begin the path");
  EXPECT_EQ(error_of("M 0 0 L 1 x"), "character 11 ('x'): expected a number for L (x y)");
  EXPECT_EQ(error_of("M 0 0 L 1"), "end of the path (character 10): expected a number for L (x y)");
  EXPECT_EQ(error_of("M 0 0 C 1 1 2 2 Z"), "character 17 ('Z'): expected a number for C (x1 y1 x2 y2 x y)");
  EXPECT_EQ(error_of("M 0 0 L 1 1 L 0 1 Z 3"),
            "character 21 ('3'): expected a command letter (M L H V C S Q T A Z, or lower case)");
  EXPECT_EQ(error_of("M 0 0 L 1 1 X 3"),
            "character 13 ('X'): expected a command letter (M L H V C S Q T A Z, or lower case) or a number");
  EXPECT_EQ(error_of("M 0 0 A 1 1 0 2 0 1 1"),
            "character 15 ('2'): expected a flag, 0 or 1, for A (rx ry x-axis-rotation large-arc-flag sweep-flag x y)");
  EXPECT_EQ(error_of("M 0 0 L 1e999 0 L 1 1"), "character 9 ('1'): expected a number of magnitude at most 1e9 for L");
  EXPECT_EQ(error_of("M 0 0 L 1e 0 L 1 1"), "character 10 ('e'): expected a number for L (x y)");
  EXPECT_EQ(error_of("M 0 0 L . 0"), "character 9 ('.'): expected a number for L (x y)");
  EXPECT_EQ(error_of("M 0 0 L 1 1 Z"), "character 1 ('M'): the subpath beginning here has fewer than 3 distinct points");
  EXPECT_EQ(error_of("M 0 0 L 1 1 L 2 2 Z"), "character 1 ('M'): the subpath beginning here encloses no area");
  EXPECT_EQ(error_of("M 0 0 H 4 V 4 Z M 9 9"), "character 17 ('M'): the subpath beginning here has fewer than 3 distinct points");
  EXPECT_EQ(error_of("M 0 0 H 4 V 4 Z\tm\xff"), "character 18 (0xff): expected a number for m (x y)");
  EXPECT_EQ(error_of("M 0 0 C 0 100 100 100 100 0 Z", 1e-6, 500),
            "character 7 ('C'): the path flattens to more than 500 points: raise the tolerance or simplify the path");
  EXPECT_EQ(error_of("M 0 0 A 100 100 0 0 1 200 0 Z", 1e-6, 500),
            "character 7 ('A'): the path flattens to more than 500 points: raise the tolerance or simplify the path");
}

TEST(SvgPath, DocumentPathsInOrderWithTheirLines) {
  const std::string svg = R"(<?xml version="1.0"?>
<!-- a comment with <path d="M 9 9"/> in it -->
<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 10 10">
  <path id="a" d="M 0 0 H 10 V 10 H 0 Z"/>
  <g><svg:path
      fill='none' d='M 2 2 H 4 V 4 H 2 Z'></svg:path></g>
  <rect x="1" y="1" width="1" height="1"/>
</svg>
)";
  const std::vector<SvgPathElement> paths = svg_document_paths(svg);
  ASSERT_EQ(paths.size(), 2u);
  EXPECT_EQ(paths[0].d, "M 0 0 H 10 V 10 H 0 Z");
  EXPECT_EQ(paths[0].line, 4);
  EXPECT_EQ(paths[1].d, "M 2 2 H 4 V 4 H 2 Z");
  EXPECT_EQ(paths[1].line, 5);
  auto error = [](const std::string& text) {
    try {
      svg_document_paths(text);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(error("<svg>\n<g transform=\"scale(2)\">\n<path d=\"M 0 0 H 1 V 1 Z\"/></g></svg>"),
            "line 2: <g> has a \"transform\" attribute, which is not applied: flatten the transforms into the path "
            "data first (in Inkscape: Path > Object to Path, then ungroup)");
  EXPECT_EQ(error("<svg>\n<rect width=\"1\" height=\"1\"/></svg>"),
            "no <path d=\"...\"> element (shapes such as <rect> and text are not read: convert them to paths first)");
  EXPECT_EQ(error("<svg>\n\n<path fill=\"red\"/></svg>"), "line 3: <path> without a \"d\" attribute");
  EXPECT_EQ(error("<svg>\n<path d=\"M 0 0 H 1 V 1 Z/></svg>"), "line 2: not well-formed XML: Error parsing element attribute");
  EXPECT_EQ(error("<svg><!-- open"), "line 1: not well-formed XML: Error parsing comment");
}

// What an XML parser reads differently from what a person sees is refused: a document type (its entities can
// hold elements), a repeated attribute, a transform in a style, an entity in d.
TEST(SvgPath, DocumentTypesRepeatedAttributesAndStyleTransformsAreRefused) {
  auto error = [](const std::string& text) {
    try {
      svg_document_paths(text);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(error("<!DOCTYPE svg [<!ENTITY p \"<path d='M 0 0 H 9 V 9 Z'/>\">]>\n<svg>&p;</svg>"),
            "line 1: the document type declaration (<!DOCTYPE ...>) is refused: its entities could add to or hide the "
            "shape");
  EXPECT_EQ(error("<svg>\n<path d=\"M 0 0 H 1 V 1 Z\" fill=\"red\" d=\"M 0 0 H 9 V 9 Z\"/></svg>"),
            "line 2: <path> has the attribute d twice");
  EXPECT_EQ(error("<svg>\n\n<path style=\"fill:red;transform:scale(2)\" d=\"M 0 0 H 1 V 1 Z\"/></svg>"),
            "line 3: <path> has a \"transform\" in its style, which is not applied: flatten the transforms into the "
            "path data first (in Inkscape: Path > Object to Path, then ungroup)");
  EXPECT_EQ(error("<svg><path d=\"M 0 0 H 1 V 1 &amp; Z\"/></svg>"), "line 1: <path>'s d holds an entity reference (&...;)");
  // A style without a transform, and a property whose name merely ends in "transform", are read.
  EXPECT_EQ(error("<svg><path style=\"fill:red; text-transform: none\" d=\"M 0 0 H 1 V 1 Z\"/></svg>"), "accepted");
}

}  // namespace
}  // namespace kf
