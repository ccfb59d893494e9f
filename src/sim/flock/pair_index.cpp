#include "sim/flock/pair_index.h"

#include <algorithm>

namespace kf {

void PairIndex::build(const NeighborLists& owned) {
  const int p = owned.agents();
  start_.assign(p + 1, 0);
  slot_.resize(owned.entries());
  for (int k = 0; k < owned.entries(); ++k) ++start_[owned.entry(k) + 1];
  for (int i = 0; i < p; ++i) start_[i + 1] += start_[i];
  // Owners visited in the lists' order, so each agent's mirrored pairs come out sorted by owner. start_
  // serves as the cursor and ends shifted by one agent.
  for (int i : owned.order())
    for (int k = owned.start(i), end = owned.start(i + 1); k < end; ++k) slot_[start_[owned.entry(k)]++] = k;
  std::copy_backward(start_.begin(), start_.end() - 1, start_.end());
  start_[0] = 0;
}

}  // namespace kf
