#pragma once
// A renderer back end: turns one frame's geometry into an RGB image.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "render/camera.h"
#include "render/geometry/frame_geometry.h"
#include "render/image/png_io.h"
#include "scene/render_spec.h"

namespace kf::render {

struct RenderSettings {
  int width = 640, height = 480;  // pixels
  int spp = 0;                    // samples per pixel; 0: the back end's default
};

class Backend {
 public:
  virtual ~Backend() = default;
  // Renders `geometry` seen by `camera` with the lights and colours of `look`. Returns an RGB image
  // of settings.width x settings.height. The same inputs give the same pixels.
  virtual Image render(const FrameGeometry& geometry, const Camera& camera, const RenderSpec& look,
                       const RenderSettings& settings) = 0;
};

// Names of the back ends ("osmesa", "embree"), in the order --help lists them.
std::vector<std::string> backend_names();
// Creates a back end by name; throws InputError naming the choices for an unknown one.
std::unique_ptr<Backend> make_backend(const std::string& name);
// Samples per pixel of the named back end when RenderSettings::spp is 0 (osmesa: 4, embree: look.samples).
int default_spp(const std::string& name, const RenderSpec& look);

// Constructors of the individual back ends (raster/, rt/).
std::unique_ptr<Backend> make_raster_backend();
std::unique_ptr<Backend> make_rt_backend();

}  // namespace kf::render
