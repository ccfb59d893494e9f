#pragma once
// Owning handles for Embree 3 devices, scenes and geometries (release on destruction, move-only), for the
// renderer's ray tracer and the character's closest-point queries alike.
#include <embree3/rtcore.h>

#include <stdexcept>
#include <string>
#include <utility>

namespace kf {

template <class Handle, void (*Release)(Handle)>
class EmbreeHandle {
 public:
  EmbreeHandle() = default;
  explicit EmbreeHandle(Handle h) : h_(h) {}
  EmbreeHandle(const EmbreeHandle&) = delete;
  EmbreeHandle& operator=(const EmbreeHandle&) = delete;
  EmbreeHandle(EmbreeHandle&& o) noexcept : h_(std::exchange(o.h_, nullptr)) {}
  EmbreeHandle& operator=(EmbreeHandle&& o) noexcept {
    if (this != &o) {
      reset();
      h_ = std::exchange(o.h_, nullptr);
    }
    return *this;
  }
  ~EmbreeHandle() { reset(); }
  void reset() {
    if (h_) Release(h_);
    h_ = nullptr;
  }
  Handle get() const { return h_; }
  explicit operator bool() const { return h_ != nullptr; }

 private:
  Handle h_ = nullptr;
};

using EmbreeDevice = EmbreeHandle<RTCDevice, rtcReleaseDevice>;
using EmbreeScene = EmbreeHandle<RTCScene, rtcReleaseScene>;
using EmbreeGeometry = EmbreeHandle<RTCGeometry, rtcReleaseGeometry>;

// A new device. Throws std::runtime_error when Embree cannot start (e.g. an unsupported CPU).
inline EmbreeDevice new_embree_device() {
  EmbreeDevice device(rtcNewDevice(nullptr));
  if (!device)
    throw std::runtime_error("Embree could not create a device (error " +
                             std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
  return device;
}

// A scene whose geometry moves every frame: dynamic, cheap top-level builds.
inline EmbreeScene new_dynamic_scene(const EmbreeDevice& device) {
  EmbreeScene scene(rtcNewScene(device.get()));
  rtcSetSceneFlags(scene.get(), RTC_SCENE_FLAG_DYNAMIC);
  rtcSetSceneBuildQuality(scene.get(), RTC_BUILD_QUALITY_LOW);
  return scene;
}

}  // namespace kf
