#pragma once
// Triangle primitives both back ends draw: flat facets, ribbons on a plane, discs, the collider shapes and
// target markers, appended to a Mesh (positions in metres, world frame; colours RGB in [0, 1]).
#include <vector>

#include "render/geometry/frame_geometry.h"

namespace kf::render {

// Appends one vertex with its front and back colour; returns its index.
uint32_t add_vertex(Mesh& m, const Vec3& p, const Vec3& n, const Vec3& front, const Vec3& back);
// A triangle (counter-clockwise seen from the front) with its face normal, one colour both sides.
void add_flat_triangle(Mesh& m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& color);
// The quad a-b-c-d with normal n.
void add_flat_quad(Mesh& m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& n,
                   const Vec3& color);
// A unit vector perpendicular to the unit vector n.
Vec3 any_perpendicular(const Vec3& n);
// A band of `width` (m) along `points` in the plane with normal n (closed: back to the first point).
void add_ribbon(Mesh& m, const std::vector<Vec3>& points, bool closed, double width, const Vec3& n,
                const Vec3& color);
// `segments` points on the circle of `radius` around c in the plane with normal n.
std::vector<Vec3> circle_points(const Vec3& c, const Vec3& n, double radius, int segments);
void add_disc(Mesh& m, const Vec3& c, const Vec3& n, double radius, const Vec3& color);
void add_sphere(Mesh& m, const Vec3& center, double r, const Vec3& color);
// Major radius R around `axis`, tube radius r.
void add_torus(Mesh& m, const Vec3& center, const Vec3& axis, double R, double r, const Vec3& color);
void add_capsule(Mesh& m, const Vec3& a, const Vec3& b, double r, const Vec3& color);
// A box with rounded edges: the points within r of the box centred at c with unit axes `axes` (columns)
// and half extents `half` (each may be 0): one closed surface, every vertex on it.
void add_rounded_box(Mesh& m, const Vec3& c, const Mat3& axes, const Vec3& half, double r, const Vec3& color);
// Three crossed bars of half-size s (m) at c: a keyframe target.
void add_marker(Mesh& m, const Vec3& c, double s, const Vec3& color);
// (1 - t) a + t b.
Vec3 mix(const Vec3& a, const Vec3& b, double t);

}  // namespace kf::render
