#pragma once
// RAII owners of Embree 3 devices and scenes; every Embree call of the renderer stays behind rt/.
#include <embree3/rtcore.h>

#include <stdexcept>
#include <string>

namespace kf::render {

class EmbreeDevice {
 public:
  // Throws std::runtime_error when Embree cannot start (e.g. an unsupported CPU).
  EmbreeDevice() : device_(rtcNewDevice(nullptr)) {
    if (!device_) throw std::runtime_error("Embree could not create a device (error " +
                                           std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
  }
  ~EmbreeDevice() { rtcReleaseDevice(device_); }
  EmbreeDevice(const EmbreeDevice&) = delete;
  EmbreeDevice& operator=(const EmbreeDevice&) = delete;
  RTCDevice get() const { return device_; }

 private:
  RTCDevice device_;
};

class EmbreeScene {
 public:
  explicit EmbreeScene(const EmbreeDevice& device) : scene_(rtcNewScene(device.get())) {
    // Geometry moves every frame: dynamic scene, cheap top-level builds.
    rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_DYNAMIC);
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_LOW);
  }
  ~EmbreeScene() { rtcReleaseScene(scene_); }
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;
  RTCScene get() const { return scene_; }

 private:
  RTCScene scene_;
};

}  // namespace kf::render
