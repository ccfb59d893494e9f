#include "sim/cloth/warm_start.h"

#include <algorithm>

namespace kf {

void WarmStart::resize(int size) {
  size_ = size;
  count_ = 0;
  for (VecX& s : s_) s.setZero(size);
}

bool WarmStart::guess(int n, VecX& x) const {
  if (count_ == 0 || n != last_ + direction_) return false;
  if (count_ == 1) x = s_[0];
  else if (count_ == 2) x = 2 * s_[0] - s_[1];
  else x = 3 * s_[0] - 3 * s_[1] + s_[2];
  return true;
}

void WarmStart::remember(int n, const VecX& x) {
  if (count_ > 0 && n == last_ + direction_) {
    s_[2].swap(s_[1]);  // the oldest's storage takes the newest
    s_[1].swap(s_[0]);
    count_ = std::min(3, count_ + 1);
  } else {
    count_ = 1;
  }
  s_[0] = x;
  last_ = n;
}

void WarmStart::save(int n, VecX& context) const {
  const int k = (count_ > 0 && n == last_ + direction_) ? count_ : 0;
  context.resize(k * size_);
  for (int i = 0; i < k; ++i) context.segment(i * size_, size_) = s_[i];
}

void WarmStart::restore(int n, const VecX& context) {
  count_ = size_ > 0 && context.size() % size_ == 0 ? int(std::min<Eigen::Index>(3, context.size() / size_)) : 0;
  for (int i = 0; i < count_; ++i) s_[i] = context.segment(i * size_, size_);
  last_ = n - direction_;
}

}  // namespace kf
