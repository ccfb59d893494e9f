// OSMesa raster back end: 4x MSAA, depth test, two-sided lit surfaces, planar shadows on the ground.
#include <GL/osmesa.h>
#include <GL/glext.h>

#include <array>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

#include "render/backend.h"
#include "render/raster/osmesa_context.h"
#include "render/shading.h"

namespace kf::render {

namespace {

constexpr const char* kVertexShader = R"(#version 450 core
layout(location = 0) in vec3 p;
layout(location = 1) in vec3 n;
layout(location = 2) in vec3 front;
layout(location = 3) in vec3 back;
uniform mat4 view_proj;
uniform int shadow_pass;
uniform vec3 light_dir;
uniform vec4 plane;
out vec3 v_pos, v_n, v_front, v_back;
void main() {
  vec3 q = p;
  if (shadow_pass == 1) {
    // Slide the point along the light onto the ground plane.
    float h = dot(plane.xyz, p) - plane.w;
    q = p - light_dir * (h / max(dot(plane.xyz, light_dir), 1e-3));
  }
  v_pos = p; v_n = n; v_front = front; v_back = back;
  gl_Position = view_proj * vec4(q, 1.0);
}
)";

// The shared lighting (render/shading.h) goes between the two halves.
constexpr const char* kFragmentHead = R"(#version 450 core
)";
constexpr const char* kFragmentMain = R"(in vec3 v_pos, v_n, v_front, v_back;
uniform int shadow_pass;
uniform vec3 light_dir;
uniform vec3 eye;
uniform float ambient;
uniform float norm_k;
uniform float shadow_alpha;
out vec4 color;
void main() {
  if (shadow_pass == 1) { color = vec4(0.0, 0.0, 0.0, shadow_alpha); return; }
  vec3 nn = normalize(v_n);
  vec3 albedo = v_front;
  // The side facing the eye decides the colour, so the cloth is two-sided whatever its winding.
  if (dot(nn, eye - v_pos) < 0.0) { nn = -nn; albedo = v_back; }
  float sky = sky_light(nn.y);
  float sun = max(dot(nn, light_dir), 0.0);
  color = vec4(albedo * (ambient * sky + sun) * norm_k, 1.0);
}
)";

GLuint compile(GLenum type, const char* src) {
  GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("shader compilation failed: ") + log);
  }
  return s;
}

// One mesh on the GPU: vertex array, vertex and index buffers.
struct GpuMesh {
  GLuint vao = 0, vbo = 0, ibo = 0;
  GLsizei count = 0;
  void create() {
    glGenVertexArrays(1, &vao);
    glGenBuffers(1, &vbo);
    glGenBuffers(1, &ibo);
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
    for (int a = 0; a < 4; ++a) {
      glEnableVertexAttribArray(a);
      glVertexAttribPointer(a, 3, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                            reinterpret_cast<const void*>(size_t(a) * 3 * sizeof(float)));
    }
    glBindVertexArray(0);
  }
  void upload(const Mesh& m) {
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(m.vertices.size() * sizeof(Vertex)), m.vertices.data(),
                 GL_STREAM_DRAW);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(m.indices.size() * sizeof(uint32_t)), m.indices.data(),
                 GL_STREAM_DRAW);
    count = GLsizei(m.indices.size());
    glBindVertexArray(0);
  }
  void draw() const {
    if (count == 0) return;
    glBindVertexArray(vao);
    glDrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, nullptr);
  }
};

class RasterBackend final : public Backend {
 public:
  Image render(const FrameGeometry& g, const Camera& camera, const RenderSpec& look,
               const RenderSettings& settings) override {
    setup(settings.width, settings.height, settings.spp > 0 ? settings.spp : 4);
    upload_meshes(g);
    set_uniforms(g, camera, look);
    draw_passes(look);
    return read_back();
  }

  ~RasterBackend() override {
    if (!context_) return;
    context_->make_current();
    release_targets();
    for (auto& m : meshes_) {
      glDeleteVertexArrays(1, &m.vao);
      glDeleteBuffers(1, &m.vbo);
      glDeleteBuffers(1, &m.ibo);
    }
    glDeleteProgram(program_);
  }

 private:
  void upload_meshes(const FrameGeometry& g) {
    if (g.ground_id != ground_id_) {  // the ground rarely changes between frames
      meshes_[0].upload(g.ground);
      ground_id_ = g.ground_id;
    }
    meshes_[1].upload(g.marks);
    meshes_[2].upload(g.objects);
  }

  void set_uniforms(const FrameGeometry& g, const Camera& camera, const RenderSpec& look) {
    const Vec3 center = camera.target;
    const double reach = (camera.eye - center).norm() + 40.0 * g.scale;
    const Eigen::Matrix4f vp = (camera.projection(std::max(1e-3 * reach, 0.02 * (camera.eye - center).norm()), reach) *
                                camera.view()).cast<float>();
    const Vec3 L = look.light_direction;
    const double lift = 0.004 * g.scale;
    glUseProgram(program_);
    glUniformMatrix4fv(loc("view_proj"), 1, GL_FALSE, vp.data());
    glUniform3f(loc("light_dir"), float(L.x()), float(L.y()), float(L.z()));
    glUniform3f(loc("eye"), float(camera.eye.x()), float(camera.eye.y()), float(camera.eye.z()));
    glUniform4f(loc("plane"), float(g.plane.normal.x()), float(g.plane.normal.y()), float(g.plane.normal.z()),
                float(g.plane.offset + lift));
    const Lighting light = lighting(look, g.plane);
    glUniform1f(loc("ambient"), light.ambient);
    glUniform1f(loc("norm_k"), light.norm_k);
    glUniform1f(loc("shadow_alpha"), light.shadow_alpha);
  }

  // Ground, then the marks on it, then the objects' shadows on the ground, then the objects.
  void draw_passes(const RenderSpec& look) {
    glBindFramebuffer(GL_FRAMEBUFFER, msaa_fbo_);
    glViewport(0, 0, width_, height_);
    glClearColor(float(look.background.x()), float(look.background.y()), float(look.background.z()), 1.0f);
    glClearStencil(0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDisable(GL_CULL_FACE);
    glUniform1i(loc("shadow_pass"), 0);
    meshes_[0].draw();
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(-1.0f, -2.0f);
    meshes_[1].draw();
    if (meshes_[0].count > 0) draw_shadows();
    glDisable(GL_POLYGON_OFFSET_FILL);
    meshes_[2].draw();
  }

  // Each ground pixel is darkened once however many objects shade it (stencil).
  void draw_shadows() {
    glUniform1i(loc("shadow_pass"), 1);
    glPolygonOffset(-2.0f, -4.0f);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glEnable(GL_STENCIL_TEST);
    glStencilFunc(GL_EQUAL, 0, 0xff);
    glStencilOp(GL_KEEP, GL_KEEP, GL_INCR);
    meshes_[2].draw();
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glUniform1i(loc("shadow_pass"), 0);
  }

  // Resolve the multisampled target, read RGB straight into the image, then flip it row by row (OpenGL's
  // rows start at the bottom): a per-channel copy loop cost as much as drawing the frame.
  Image read_back() {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, msaa_fbo_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo_);
    glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_fbo_);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    Image img(width_, height_, 3);
    glReadPixels(0, 0, width_, height_, GL_RGB, GL_UNSIGNED_BYTE, img.pixels.data());
    if (GLenum e = glGetError(); e != GL_NO_ERROR)
      throw std::runtime_error("OpenGL error " + std::to_string(e) + " while rendering");
    const size_t row = size_t(width_) * 3;
    row_.resize(row);
    for (int y = 0; y < height_ / 2; ++y) {
      uint8_t* a = img.at(0, y);
      uint8_t* b = img.at(0, height_ - 1 - y);
      std::memcpy(row_.data(), a, row);
      std::memcpy(a, b, row);
      std::memcpy(b, row_.data(), row);
    }
    return img;
  }

  GLint loc(const char* name) const { return glGetUniformLocation(program_, name); }

  void setup(int width, int height, int samples) {
    if (!context_) {
      context_ = std::make_unique<OsMesaContext>(width, height);
      const std::string fragment = std::string(kFragmentHead) + kSkyLightGlsl + kFragmentMain;
      const GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader), fs = compile(GL_FRAGMENT_SHADER, fragment.c_str());
      program_ = glCreateProgram();
      glAttachShader(program_, vs);
      glAttachShader(program_, fs);
      glLinkProgram(program_);
      glDeleteShader(vs);
      glDeleteShader(fs);
      GLint ok = 0;
      glGetProgramiv(program_, GL_LINK_STATUS, &ok);
      if (!ok) throw std::runtime_error("shader link failed");
      for (auto& m : meshes_) m.create();
    } else {
      context_->make_current();
    }
    GLint max_samples = 1;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    samples = std::min(samples, int(max_samples));
    if (width == width_ && height == height_ && samples == samples_) return;
    if (width != context_->width() || height != context_->height()) context_->resize(width, height);
    release_targets();
    width_ = width;
    height_ = height;
    samples_ = samples;
    glGenRenderbuffers(2, msaa_rb_);
    glBindRenderbuffer(GL_RENDERBUFFER, msaa_rb_[0]);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, msaa_rb_[1]);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH24_STENCIL8, width, height);
    glGenFramebuffers(1, &msaa_fbo_);
    glBindFramebuffer(GL_FRAMEBUFFER, msaa_fbo_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, msaa_rb_[0]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, msaa_rb_[1]);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("multisample framebuffer incomplete");
    glGenRenderbuffers(1, &resolve_rb_);
    glBindRenderbuffer(GL_RENDERBUFFER, resolve_rb_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glGenFramebuffers(1, &resolve_fbo_);
    glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolve_rb_);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw std::runtime_error("resolve framebuffer incomplete");
  }

  void release_targets() {
    if (msaa_fbo_) glDeleteFramebuffers(1, &msaa_fbo_);
    if (resolve_fbo_) glDeleteFramebuffers(1, &resolve_fbo_);
    if (msaa_rb_[0]) glDeleteRenderbuffers(2, msaa_rb_);
    if (resolve_rb_) glDeleteRenderbuffers(1, &resolve_rb_);
    msaa_fbo_ = resolve_fbo_ = resolve_rb_ = msaa_rb_[0] = msaa_rb_[1] = 0;
  }

  std::unique_ptr<OsMesaContext> context_;
  GLuint program_ = 0;
  GLuint msaa_fbo_ = 0, resolve_fbo_ = 0, msaa_rb_[2] = {0, 0}, resolve_rb_ = 0;
  int width_ = 0, height_ = 0, samples_ = 0;
  long ground_id_ = -1;
  std::array<GpuMesh, 3> meshes_;  // ground, marks, objects
  std::vector<unsigned char> row_;  // one image row, for the vertical flip
};

}  // namespace

std::unique_ptr<Backend> make_raster_backend() { return std::make_unique<RasterBackend>(); }

}  // namespace kf::render
