#include "render/geometry/primitives.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace kf::render {

namespace {

void set3(float* d, const Vec3& v) {
  d[0] = float(v.x());
  d[1] = float(v.y());
  d[2] = float(v.z());
}

template <class Surface>
void add_periodic_surface(Mesh& m, int nu, int nv, const Vec3& color, Surface surface) {
  const uint32_t base = uint32_t(m.vertices.size());
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      Vec3 p, n;
      surface(2.0 * M_PI * i / nu, 2.0 * M_PI * j / nv, p, n);
      add_vertex(m, p, n, color, color);
    }
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const uint32_t a = base + j * (nu + 1) + i, b = a + 1, c = a + (nu + 1) + 1, d = a + (nu + 1);
      m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
    }
}

}  // namespace

uint32_t add_vertex(Mesh& m, const Vec3& p, const Vec3& n, const Vec3& front, const Vec3& back) {
  Vertex v;
  set3(v.p, p);
  set3(v.n, n);
  set3(v.front, front);
  set3(v.back, back);
  m.vertices.push_back(v);
  return uint32_t(m.vertices.size() - 1);
}

// A flat triangle, front side counter-clockwise.
void add_flat_triangle(Mesh& m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& color) {
  const Vec3 n = (b - a).cross(c - a).normalized();
  const uint32_t i = add_vertex(m, a, n, color, color);
  add_vertex(m, b, n, color, color);
  add_vertex(m, c, n, color, color);
  m.indices.insert(m.indices.end(), {i, i + 1, i + 2});
}

// Quad a b c d counter-clockwise seen from the front side, flat.
void add_flat_quad(Mesh& m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& n,
                   const Vec3& color) {
  const uint32_t i = add_vertex(m, a, n, color, color);
  add_vertex(m, b, n, color, color);
  add_vertex(m, c, n, color, color);
  add_vertex(m, d, n, color, color);
  m.indices.insert(m.indices.end(), {i, i + 1, i + 2, i, i + 2, i + 3});
}

Vec3 any_perpendicular(const Vec3& n) {
  const Vec3 a = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitZ();
  return n.cross(a).normalized();
}

// A strip of `width` metres along `points` lying in the plane with normal `n`.
void add_ribbon(Mesh& m, const std::vector<Vec3>& points, bool closed, double width, const Vec3& n,
                const Vec3& color) {
  const size_t count = points.size();
  if (count < 2) return;
  const size_t segments = closed ? count : count - 1;
  for (size_t s = 0; s < segments; ++s) {
    const Vec3 a = points[s], b = points[(s + 1) % count];
    const Vec3 d = b - a;
    if (d.norm() < 1e-12) continue;
    const Vec3 t = d.normalized();
    const Vec3 side = n.cross(t) * (0.5 * width);
    // Extending each segment by half a width closes the gaps at the corners.
    const Vec3 a2 = a - t * (0.5 * width), b2 = b + t * (0.5 * width);
    add_flat_quad(m, a2 - side, b2 - side, b2 + side, a2 + side, n, color);
  }
}

std::vector<Vec3> circle_points(const Vec3& c, const Vec3& n, double radius, int segments) {
  const Vec3 u = any_perpendicular(n), w = n.cross(u);
  std::vector<Vec3> pts;
  for (int k = 0; k < segments; ++k) {
    const double a = 2.0 * M_PI * k / segments;
    pts.push_back(c + radius * (std::cos(a) * u + std::sin(a) * w));
  }
  return pts;
}

void add_disc(Mesh& m, const Vec3& c, const Vec3& n, double radius, const Vec3& color) {
  const auto pts = circle_points(c, n, radius, 24);
  const uint32_t center = add_vertex(m, c, n, color, color);
  for (size_t k = 0; k < pts.size(); ++k) add_vertex(m, pts[k], n, color, color);
  for (uint32_t k = 0; k < pts.size(); ++k)
    m.indices.insert(m.indices.end(), {center, center + 1 + k, center + 1 + (k + 1) % uint32_t(pts.size())});
}

// A smooth surface from a (u, v) parameterisation with `nu` x `nv` quads, both directions periodic.

void add_sphere(Mesh& m, const Vec3& center, double r, const Vec3& color) {
  add_periodic_surface(m, 48, 24, color, [&](double u, double v, Vec3& p, Vec3& n) {
    const double theta = 0.5 * v;  // 0..pi
    n = Vec3(std::sin(theta) * std::cos(u), std::cos(theta), -std::sin(theta) * std::sin(u));
    p = center + r * n;
  });
}

void add_torus(Mesh& m, const Vec3& center, const Vec3& axis, double R, double r, const Vec3& color) {
  const Vec3 a = axis.normalized(), e1 = any_perpendicular(a), e2 = a.cross(e1);
  add_periodic_surface(m, 64, 20, color, [&](double u, double v, Vec3& p, Vec3& n) {
    const Vec3 radial = std::cos(u) * e1 + std::sin(u) * e2;
    n = std::cos(v) * radial + std::sin(v) * a;
    p = center + R * radial + r * n;
  });
}

// A capsule: the hemisphere at b (rows 0..kRows), the cylinder (one band), the hemisphere at a.
void add_capsule(Mesh& m, const Vec3& a, const Vec3& b, double r, const Vec3& color) {
  const Vec3 e = (b - a).normalized(), e1 = any_perpendicular(e), e2 = e.cross(e1);
  constexpr int kRows = 12;  // per cap
  add_periodic_surface(m, 48, 2 * kRows + 1, color, [&](double u, double v, Vec3& p, Vec3& n) {
    const int j = int(std::lround(v * (2 * kRows + 1) / (2.0 * M_PI)));
    const bool at_b = j <= kRows;
    const double theta = 0.5 * M_PI * (at_b ? j : j - 1) / kRows;  // from b's pole (0) to a's (pi)
    n = std::cos(theta) * e + std::sin(theta) * (std::cos(u) * e1 + std::sin(u) * e2);
    p = (at_b ? b : a) + r * n;
  });
}

void add_rounded_box(Mesh& m, const Vec3& c, const Mat3& axes, const Vec3& half, double r, const Vec3& color) {
  // A sphere of radius r split at its three great circles, each octant moved out to its corner of the
  // box: every angle where a sign changes is taken twice (once per side), so the strips between them are
  // the flat faces and the edges' cylinders. Only the two faces across axis 1 (at the poles) are added flat.
  constexpr int kArc = 6;              // segments per quarter circle
  constexpr int kU = 4 * (kArc + 1);   // around axis 1 (columns; the last strip closes the loop)
  constexpr int kV = 2 * (kArc + 1);   // pole to pole (rows)
  const uint32_t base = uint32_t(m.vertices.size());
  for (int j = 0; j < kV; ++j) {
    const int hemi = j / (kArc + 1), jj = j % (kArc + 1);
    const double theta = 0.5 * M_PI * (hemi + double(jj) / kArc);
    for (int i = 0; i < kU; ++i) {
      const int quarter = i / (kArc + 1), ii = i % (kArc + 1);
      const double phi = 0.5 * M_PI * (quarter + double(ii) / kArc), mid = 0.5 * M_PI * (quarter + 0.5);
      const Vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
      const Vec3 sign(std::cos(mid) > 0 ? 1 : -1, hemi == 0 ? 1 : -1, -std::sin(mid) > 0 ? 1 : -1);
      add_vertex(m, c + axes * (half.cwiseProduct(sign) + r * n), axes * n, color, color);
    }
  }
  for (int j = 0; j + 1 < kV; ++j)
    for (int i = 0; i < kU; ++i) {
      const uint32_t a = base + j * kU + i, b = base + j * kU + (i + 1) % kU, d = a + kU, e = b + kU;
      m.indices.insert(m.indices.end(), {a, b, e, a, e, d});
    }
  for (const double side : {-1.0, 1.0}) {
    const Vec3 n = side * axes.col(1), mid = c + axes.col(1) * (side * (half.y() + r));
    const Vec3 ua = axes.col(0) * half.x(), ub = axes.col(2) * half.z();
    if (side > 0) add_flat_quad(m, mid - ua + ub, mid + ua + ub, mid + ua - ub, mid - ua - ub, n, color);
    else add_flat_quad(m, mid - ua - ub, mid + ua - ub, mid + ua + ub, mid - ua + ub, n, color);
  }
}

// Small octahedron: a target point in space.
void add_marker(Mesh& m, const Vec3& c, double s, const Vec3& color) {
  const Vec3 X = Vec3::UnitX() * s, Y = Vec3::UnitY() * s, Z = Vec3::UnitZ() * s;
  const Vec3 dirs[4] = {X, Z, -X, -Z};
  for (int k = 0; k < 4; ++k) {
    add_flat_triangle(m, c + Y, c + dirs[k], c + dirs[(k + 1) % 4], color);
    add_flat_triangle(m, c - Y, c + dirs[(k + 1) % 4], c + dirs[k], color);
  }
}

Vec3 mix(const Vec3& a, const Vec3& b, double t) { return (1 - t) * a + t * b; }

}  // namespace kf::render
