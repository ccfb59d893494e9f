#include "sim/character/closest_point_triangle.h"

namespace kf {

TrianglePoint closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  using F = TriangleFeature;
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {a, Vec3(1, 0, 0), F::kVertexA};

  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {b, Vec3(0, 1, 0), F::kVertexB};

  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return {a + v * ab, Vec3(1 - v, v, 0), F::kEdgeAB};
  }

  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {c, Vec3(0, 0, 1), F::kVertexC};

  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    return {a + w * ac, Vec3(1 - w, 0, w), F::kEdgeCA};
  }

  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {b + w * (c - b), Vec3(0, 1 - w, w), F::kEdgeBC};
  }

  const double sum = va + vb + vc;
  if (!(sum > 0.0)) return {a, Vec3(1, 0, 0), F::kVertexA};  // degenerate: every region test was borderline
  const double v = vb / sum, w = vc / sum;
  return {a + v * ab + w * ac, Vec3(1 - v - w, v, w), F::kFace};
}

}  // namespace kf
