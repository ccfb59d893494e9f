// Embree back end: path-traced direct light from a sun of finite size (soft shadows) plus sky light with
// ambient occlusion, N jittered samples per pixel, tiles in parallel with TBB.
//
// Every pixel seeds its own random sequence from its coordinates, so the image does not depend on the
// thread count or the tile schedule.
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "render/backend.h"
#include "core/embree_handles.h"
#include "render/shading.h"

namespace kf::render {

namespace {

uint32_t pcg_hash(uint32_t v) {
  const uint32_t state = v * 747796405u + 2891336453u;
  const uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// A random direction in the plane as (cos, sin) from a table: the sin/cos calls of two samples per
// ray were an eighth of the frame time, and 4,096 angles are finer than any noise they make.
struct UnitCircle {
  static constexpr int kBits = 12;
  std::array<float, 2 << kBits> cs;
  UnitCircle() {
    for (int i = 0; i < (1 << kBits); ++i) {
      const double a = 2 * M_PI * (i + 0.5) / (1 << kBits);
      cs[2 * i] = float(std::cos(a));
      cs[2 * i + 1] = float(std::sin(a));
    }
  }
};
const UnitCircle kCircle;

struct Rng {
  uint32_t s;
  float next() {
    s = pcg_hash(s);
    return float(s >> 8) * (1.0f / 16777216.0f);
  }
  // A uniformly random angle's cosine and sine.
  void angle(float& c, float& sn) {
    s = pcg_hash(s);
    const uint32_t i = s >> (32 - UnitCircle::kBits);
    c = kCircle.cs[2 * i];
    sn = kCircle.cs[2 * i + 1];
  }
};

struct V3 {
  float x, y, z;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(V3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
inline V3 mul(V3 a, V3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
inline float dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline V3 normalize(V3 a) { return a * (1.0f / std::sqrt(std::max(dot(a, a), 1e-30f))); }
inline V3 from(const Vec3& v) { return {float(v.x()), float(v.y()), float(v.z())}; }
inline V3 from(const float* f) { return {f[0], f[1], f[2]}; }

// A tangent frame around the unit vector n without square roots or branches on the hot path
// (Duff et al., "Building an orthonormal basis, revisited", 2017).
void orthonormal(V3 n, V3& t, V3& b) {
  const float sign = std::copysign(1.0f, n.z), a = -1.0f / (sign + n.z), c = n.x * n.y * a;
  t = {1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x};
  b = {c, sign + n.y * n.y * a, -n.y};
}

// One triangle mesh in the Embree scene, rebuilt when its size changes and refitted otherwise.
struct RtMesh {
  RTCGeometry geom = nullptr;
  unsigned id = RTC_INVALID_GEOMETRY_ID;
  size_t vertices = 0, triangles = 0;
  const Mesh* source = nullptr;  // the frame's mesh, for shading attributes

  void update(RTCDevice device, RTCScene scene, const Mesh& m, bool deforming) {
    source = &m;
    const bool same = geom && m.vertices.size() == vertices && size_t(m.triangles()) == triangles;
    if (!same) {
      release(scene);
      if (m.triangles() == 0) return;
      geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
      // Moving objects get a fresh LOW-quality build every frame (about a millisecond for 10k
      // triangles): refitting the first frame's tree degrades badly once agents fly far apart.
      rtcSetGeometryBuildQuality(geom, deforming ? RTC_BUILD_QUALITY_LOW : RTC_BUILD_QUALITY_MEDIUM);
      vertices = m.vertices.size();
      triangles = size_t(m.triangles());
      rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertices);
      auto* idx = static_cast<uint32_t*>(
          rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), triangles));
      std::copy(m.indices.begin(), m.indices.end(), idx);
      id = rtcAttachGeometry(scene, geom);
    } else {
      auto* idx = static_cast<uint32_t*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_INDEX, 0));
      std::copy(m.indices.begin(), m.indices.end(), idx);
      rtcUpdateGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0);
    }
    auto* p = static_cast<float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0));
    for (size_t i = 0; i < vertices; ++i)
      for (int c = 0; c < 3; ++c) p[3 * i + c] = m.vertices[i].p[c];
    rtcUpdateGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(geom);
  }
  void release(RTCScene scene) {
    if (!geom) return;
    rtcDetachGeometry(scene, id);
    rtcReleaseGeometry(geom);
    geom = nullptr;
    id = RTC_INVALID_GEOMETRY_ID;
    vertices = triangles = 0;
  }
};

class RtBackend final : public Backend {
 public:
  RtBackend() : device_(new_embree_device()), scene_(new_dynamic_scene(device_)) {}
  ~RtBackend() override {
    for (auto& m : meshes_) m.release(scene_.get());
  }

  Image render(const FrameGeometry& g, const Camera& camera, const RenderSpec& look,
               const RenderSettings& settings) override {
    if (g.ground_id != ground_id_) {
      meshes_[0].update(device_.get(), scene_.get(), g.ground, false);
      ground_id_ = g.ground_id;
    }
    meshes_[0].source = &g.ground;
    meshes_[1].update(device_.get(), scene_.get(), g.marks, false);
    meshes_[2].update(device_.get(), scene_.get(), g.objects, true);
    rtcCommitScene(scene_.get());

    const int W = settings.width, H = settings.height, spp = std::max(settings.spp, 1);
    Image img(W, H, 3);
    Vec3 fw, rt, up;
    camera.basis(fw, rt, up);
    const float tan_half = float(std::tan(0.5 * camera.fov * M_PI / 180.0));
    Shading sh;
    sh.eye = from(camera.eye);
    sh.forward = from(fw);
    sh.right = from(rt) * (tan_half * float(camera.aspect));
    sh.up = from(up) * tan_half;
    sh.sun = normalize(from(look.light_direction));
    orthonormal(sh.sun, sh.sun_t, sh.sun_b);
    sh.sun_radius = float(std::tan(0.5 * look.light_angle * M_PI / 180.0));
    const Lighting light = lighting(look, g.plane);
    sh.ambient = light.ambient;
    sh.norm_k = light.norm_k;
    sh.eps = float(1e-4 * g.scale);
    sh.ao_distance = float(0.5 * g.scale);
    sh.background = from(look.background);

    constexpr int kTile = 16;
    static_assert(kTile % kLanes == 0, "tiles hold whole packets");
    tbb::parallel_for(tbb::blocked_range2d<int>(0, (H + kTile - 1) / kTile, 1, 0, (W + kTile - 1) / kTile, 1),
                      [&](const tbb::blocked_range2d<int>& r) {
                        for (int ty = r.rows().begin(); ty < r.rows().end(); ++ty)
                          for (int tx = r.cols().begin(); tx < r.cols().end(); ++tx)
                            for (int y = ty * kTile; y < std::min(H, (ty + 1) * kTile); ++y)
                              for (int x = tx * kTile; x < std::min(W, (tx + 1) * kTile); x += kLanes)
                                shade_packet(sh, x, y, W, H, spp, img);
                      });
    return img;
  }

 private:
  // Rays travel in packets of 8 (one per pixel of a row run): Embree traces them about twice as fast
  // as single rays, and each pixel still draws its own random numbers in the same order.
  static constexpr int kLanes = 8;

  struct Shading {
    V3 eye, forward, right, up, sun, sun_t, sun_b, background;
    float sun_radius, ambient, norm_k, eps, ao_distance;
  };

  static void set_ray(RTCRay8& r, int l, V3 o, V3 d, float tfar) {
    r.org_x[l] = o.x, r.org_y[l] = o.y, r.org_z[l] = o.z;
    r.dir_x[l] = d.x, r.dir_y[l] = d.y, r.dir_z[l] = d.z;
    r.tnear[l] = 0.0f;
    r.tfar[l] = tfar;
    r.time[l] = 0.0f;
    r.mask[l] = ~0u;
    r.id[l] = unsigned(l);
    r.flags[l] = 0;
  }

  // Where lane l's primary ray hit: the normal facing the ray (shading n, geometric ng), the colour of the side
  // seen, and the point lifted off the surface by eps.
  struct SurfacePoint {
    V3 n, ng, p, albedo;
  };
  SurfacePoint surface_point(const Shading& sh, const RTCRayHit8& rh, int l) const {
    const V3 dir{rh.ray.dir_x[l], rh.ray.dir_y[l], rh.ray.dir_z[l]};
    const Mesh* m = nullptr;
    for (const auto& rm : meshes_)
      if (rm.id == rh.hit.geomID[l]) m = rm.source;
    const uint32_t* tri = &m->indices[size_t(rh.hit.primID[l]) * 3];
    const Vertex &a = m->vertices[tri[0]], &b = m->vertices[tri[1]], &c = m->vertices[tri[2]];
    const float u = rh.hit.u[l], v = rh.hit.v[l], w = 1.0f - u - v;
    SurfacePoint s;
    s.n = normalize(from(a.n) * w + from(b.n) * u + from(c.n) * v);
    s.albedo = from(a.front) * w + from(b.front) * u + from(c.front) * v;
    if (dot(s.n, dir) > 0.0f) {  // seen from behind: the other side's colour
      s.n = s.n * -1.0f;
      s.albedo = from(a.back) * w + from(b.back) * u + from(c.back) * v;
    }
    s.ng = normalize(V3{rh.hit.Ng_x[l], rh.hit.Ng_y[l], rh.hit.Ng_z[l]});
    if (dot(s.ng, dir) > 0.0f) s.ng = s.ng * -1.0f;
    s.p = sh.eye + dir * rh.ray.tfar[l] + s.ng * sh.eps;
    return s;
  }

  // Sun: a point on a disc of directions around the light direction. Sets n.l and, when the sun is above
  // the surface, lane l's shadow ray.
  static void sample_sun(const Shading& sh, const SurfacePoint& s, Rng& rng, int l, float& ndl, int* valid,
                         RTCRay8& rays) {
    const float r = sh.sun_radius * std::sqrt(rng.next());
    float c, sn;
    rng.angle(c, sn);
    const V3 d = normalize(sh.sun + sh.sun_t * (r * c) + sh.sun_b * (r * sn));
    ndl = dot(s.n, d);
    if (ndl > 0.0f) {
      valid[l] = -1;
      set_ray(rays, l, s.p, d, INFINITY);
    }
  }

  // Sky: a cosine-weighted direction, occluded within a short distance.
  static void sample_sky(const Shading& sh, const SurfacePoint& s, Rng& rng, int l, float& weight, int* valid,
                         RTCRay8& rays) {
    V3 t, bt;
    orthonormal(s.n, t, bt);
    const float r1 = rng.next(), rr = std::sqrt(r1);
    float c, sn;
    rng.angle(c, sn);
    const V3 d = t * (rr * c) + bt * (rr * sn) + s.n * std::sqrt(1.0f - r1);  // unit: t, bt, n are
    weight = sky_light(s.n.y);
    if (dot(d, s.ng) > 0.0f) {
      valid[l] = -1;
      set_ray(rays, l, s.p, d, sh.ao_distance);
    }
  }

  // The primary rays of one sample of pixels x0..x0+7 of row y (valid lanes only), jittered within each pixel.
  static void set_primary_rays(const Shading& sh, int x0, int y, int W, int H, const int* valid, Rng* rng,
                               RTCRayHit8& rh) {
    for (int l = 0; l < kLanes; ++l) {
      if (!valid[l]) continue;
      const float px = (float(x0 + l) + rng[l].next()) / float(W) * 2.0f - 1.0f;
      const float py = 1.0f - (float(y) + rng[l].next()) / float(H) * 2.0f;
      set_ray(rh.ray, l, sh.eye, normalize(sh.forward + sh.right * px + sh.up * py), INFINITY);
      rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
    }
  }

  // The mean of each valid lane's `spp` samples, as 8-bit RGB.
  static void write_lanes(const V3* sum, const int* valid, int x0, int y, int spp, Image& img) {
    for (int l = 0; l < kLanes; ++l) {
      if (!valid[l]) continue;
      const V3 c = sum[l] * (1.0f / float(spp));
      uint8_t* out = img.at(x0 + l, y);
      out[0] = uint8_t(std::lround(std::clamp(c.x, 0.0f, 1.0f) * 255.0f));
      out[1] = uint8_t(std::lround(std::clamp(c.y, 0.0f, 1.0f) * 255.0f));
      out[2] = uint8_t(std::lround(std::clamp(c.z, 0.0f, 1.0f) * 255.0f));
    }
  }

  // Pixels x..x+7 of row y (those inside the image), spp samples each, written into `img`.
  void shade_packet(const Shading& sh, int x0, int y, int W, int H, int spp, Image& img) const {
    alignas(32) int valid[kLanes], sun_valid[kLanes], sky_valid[kLanes];
    Rng rng[kLanes];
    V3 sum[kLanes], albedo[kLanes];
    float ndl[kLanes], sky_weight[kLanes];
    for (int l = 0; l < kLanes; ++l) {
      const int x = x0 + l;
      valid[l] = x < W ? -1 : 0;
      rng[l] = Rng{pcg_hash(uint32_t(y) * 0x9E3779B9u ^ pcg_hash(uint32_t(x)))};
      sum[l] = V3{0, 0, 0};
    }
    RTCIntersectContext primary_ctx, shadow_ctx;
    rtcInitIntersectContext(&primary_ctx);
    primary_ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcInitIntersectContext(&shadow_ctx);
    alignas(32) RTCRayHit8 rh;
    alignas(32) RTCRay8 sun_rays, sky_rays;
    for (int s = 0; s < spp; ++s) {
      set_primary_rays(sh, x0, y, W, H, valid, rng, rh);
      rtcIntersect8(valid, scene_.get(), &primary_ctx, &rh);
      for (int l = 0; l < kLanes; ++l) {
        sun_valid[l] = sky_valid[l] = 0;
        if (!valid[l]) continue;
        if (rh.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID) {
          sum[l] = sum[l] + sh.background;
          continue;
        }
        const SurfacePoint sp = surface_point(sh, rh, l);
        albedo[l] = sp.albedo;
        sample_sun(sh, sp, rng[l], l, ndl[l], sun_valid, sun_rays);
        sample_sky(sh, sp, rng[l], l, sky_weight[l], sky_valid, sky_rays);
      }
      rtcOccluded8(sun_valid, scene_.get(), &shadow_ctx, &sun_rays);
      rtcOccluded8(sky_valid, scene_.get(), &shadow_ctx, &sky_rays);
      for (int l = 0; l < kLanes; ++l) {
        if (!valid[l] || rh.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID) continue;
        // Embree marks an occluded ray with tfar = -inf.
        const float sun = sun_valid[l] && sun_rays.tfar[l] >= 0.0f ? ndl[l] : 0.0f;
        const float sky = sky_valid[l] && sky_rays.tfar[l] >= 0.0f ? sky_weight[l] : 0.0f;
        sum[l] = sum[l] + albedo[l] * ((sh.ambient * sky + sun) * sh.norm_k);
      }
    }
    write_lanes(sum, valid, x0, y, spp, img);
  }

  EmbreeDevice device_;
  EmbreeScene scene_;
  std::array<RtMesh, 3> meshes_;  // ground, marks, objects
  long ground_id_ = -1;
};

}  // namespace

std::unique_ptr<Backend> make_rt_backend() { return std::make_unique<RtBackend>(); }

}  // namespace kf::render
