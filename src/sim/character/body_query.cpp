#include "sim/character/body_query.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/check.h"

namespace kf {
namespace {

struct PointQueryState {
  const BodySurface* surface;
  Vec3 p;
  int best = -1;
  TrianglePoint best_tp;
  double best_d2 = std::numeric_limits<double>::infinity();
  float slack = 0.0f;  // covers the float rounding of the query centre
};

// Called by Embree for each triangle whose bounds touch the current search sphere; shrinking the
// radius (and returning true) lets the traversal cull everything farther than the best so far.
bool closest_triangle_callback(RTCPointQueryFunctionArguments* args) {
  auto* s = static_cast<PointQueryState*>(args->userPtr);
  const int f = static_cast<int>(args->primID);
  const TrianglePoint tp = s->surface->closest_on(f, s->p);
  const double d2 = (s->p - tp.point).squaredNorm();
  if (d2 < s->best_d2 || (d2 == s->best_d2 && f < s->best)) {
    s->best_d2 = d2;
    s->best = f;
    s->best_tp = tp;
    // Round up: the BVH works in float and must never cull a triangle that is nearer in double.
    const float r =
        std::nextafter(static_cast<float>(std::sqrt(d2)), std::numeric_limits<float>::infinity()) + s->slack;
    if (r < args->query->radius) {
      args->query->radius = r;
      return true;
    }
  }
  return false;
}

void throw_on_embree_error(RTCDevice device, const char* what) {
  const RTCError e = rtcGetDeviceError(device);
  if (e != RTC_ERROR_NONE) throw std::runtime_error(std::string("Embree error ") + std::to_string(e) + " in " + what);
}

}  // namespace

BodyQuery::BodyQuery(const TriangleIndices& triangles, int vertex_count)
    : surface_(triangles, vertex_count), device_(new_embree_device()), scene_(new_dynamic_scene(device_)) {
  EmbreeGeometry geometry(rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_TRIANGLE));
  rtcSetGeometryBuildQuality(geometry.get(), RTC_BUILD_QUALITY_REFIT);
  vertex_buffer_ = static_cast<float*>(rtcSetNewGeometryBuffer(geometry.get(), RTC_BUFFER_TYPE_VERTEX, 0,
                                                               RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertex_count));
  auto* index = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry.get(), RTC_BUFFER_TYPE_INDEX, 0,
                                                               RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles.rows()));
  for (int f = 0; f < triangles.rows(); ++f)
    for (int k = 0; k < 3; ++k) index[3 * f + k] = static_cast<unsigned>(triangles(f, k));
  for (int i = 0; i < 3 * vertex_count; ++i) vertex_buffer_[i] = 0.0f;
  rtcCommitGeometry(geometry.get());
  rtcAttachGeometryByID(scene_.get(), geometry.get(), 0);
  geometry_ = geometry.get();  // the scene keeps its own reference
  throw_on_embree_error(device_.get(), "BodyQuery setup");
}

void BodyQuery::update(const VecX& x) {
  surface_.set_vertices(x);
  for (Eigen::Index i = 0; i < x.size(); ++i) vertex_buffer_[i] = static_cast<float>(x[i]);
  if (built_) rtcUpdateGeometryBuffer(geometry_, RTC_BUFFER_TYPE_VERTEX, 0);
  rtcCommitGeometry(geometry_);
  rtcCommitScene(scene_.get());
  built_ = true;
}

BodyHit BodyQuery::closest(const Vec3& p, double radius) const {
  CHECK(built_);  // update() first
  PointQueryState state{&surface_, p};
  RTCPointQuery query;
  query.x = static_cast<float>(p.x());
  query.y = static_cast<float>(p.y());
  query.z = static_cast<float>(p.z());
  query.time = 0.0f;
  // The float query centre can be up to half an ulp away from p: widen the sphere to keep every candidate.
  const float slack = 4.0f * std::numeric_limits<float>::epsilon() * static_cast<float>(p.cwiseAbs().maxCoeff() + 1.0);
  state.slack = slack;
  query.radius = static_cast<float>(radius) + slack;
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  rtcPointQuery(scene_.get(), &query, &context, closest_triangle_callback, &state);
  if (state.best < 0 || state.best_d2 > radius * radius) return {};
  return surface_.make_hit(p, state.best, state.best_tp);
}

void BodyQuery::closest_batch(const VecX& points, double radius, std::vector<BodyHit>& hits) const {
  const int m = static_cast<int>(points.size() / 3);
  hits.resize(m);
  tbb::parallel_for(tbb::blocked_range<int>(0, m, 32), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) hits[i] = closest(seg(points, i), radius);
  });
}

}  // namespace kf
