#pragma once
// Owning handles for Embree 3 devices and scenes (release on destruction, move-only).
#include <embree3/rtcore.h>

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

}  // namespace kf
