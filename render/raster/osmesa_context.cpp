#include "render/raster/osmesa_context.h"

#include <stdexcept>
#include <string>

namespace kf::render {

OsMesaContext::OsMesaContext(int width, int height) {
  const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 8,
                         OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, 4,
                         OSMESA_CONTEXT_MINOR_VERSION, 5, 0};
  ctx_ = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!ctx_) throw std::runtime_error("OSMesa could not create an OpenGL 4.5 core context");
  resize(width, height);
}

OsMesaContext::~OsMesaContext() {
  if (ctx_) OSMesaDestroyContext(ctx_);
}

void OsMesaContext::resize(int width, int height) {
  width_ = width;
  height_ = height;
  buffer_.assign(size_t(width) * height * 4, 0);
  make_current();
}

void OsMesaContext::make_current() {
  if (!OSMesaMakeCurrent(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, width_, height_))
    throw std::runtime_error("OSMesa could not bind a " + std::to_string(width_) + "x" +
                             std::to_string(height_) + " framebuffer");
}

}  // namespace kf::render
