#pragma once
// Work space for one kind of per-pair terms at a time (PairForward in a forward pass, PairTransposed in a
// transposed one): a flock step never needs both at once, so the pair buffers cost the larger of the two
// kinds per pair rather than their sum (tens of MB each once a 10,000-agent crowd bunches).
// Asking for one kind ends the life of the other's contents. Grows by half when it must; never shrinks.
#include <algorithm>
#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>

namespace kf {

class PairBuffer {
 public:
  // Storage for `pairs` values of Pair (contents unspecified until written).
  template <class Pair>
  Pair* as(std::size_t pairs) {
    static_assert(std::is_trivially_copyable_v<Pair> && std::is_trivially_destructible_v<Pair>);
    static_assert(alignof(Pair) <= __STDCPP_DEFAULT_NEW_ALIGNMENT__);
    const std::size_t bytes = pairs * sizeof(Pair);
    if (bytes > bytes_) {
      bytes_ = std::max(bytes, bytes_ + bytes_ / 2);
      data_.reset();  // release before allocating, so the old and new never coexist
      data_.reset(new std::byte[bytes_]);
    }
    return data_ ? std::launder(reinterpret_cast<Pair*>(data_.get())) : nullptr;
  }
  std::size_t bytes() const { return bytes_; }

 private:
  std::unique_ptr<std::byte[]> data_;
  std::size_t bytes_ = 0;
};

}  // namespace kf
