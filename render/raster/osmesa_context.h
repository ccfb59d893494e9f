#pragma once
// An off-screen OpenGL 4.5 core context (OSMesa/llvmpipe), current on the creating thread while alive.
#include <vector>

#include <GL/osmesa.h>

namespace kf::render {

class OsMesaContext {
 public:
  // Throws std::runtime_error when OSMesa cannot create or bind a context.
  OsMesaContext(int width, int height);
  ~OsMesaContext();
  OsMesaContext(const OsMesaContext&) = delete;
  OsMesaContext& operator=(const OsMesaContext&) = delete;
  // Re-binds the context to a framebuffer of a new size (pixels).
  void resize(int width, int height);
  void make_current();
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  OSMesaContext ctx_ = nullptr;
  std::vector<unsigned char> buffer_;  // the default framebuffer; we draw into our own FBOs
  int width_ = 0, height_ = 0;
};

}  // namespace kf::render
