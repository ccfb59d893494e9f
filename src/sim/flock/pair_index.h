#pragma once
// Each neighbour pair once. Lists from NeighborGrid::search_owned hold every pair once, under its owner (the
// agent earlier in NeighborLists::order); pair k is entry k of those lists. The owner computes the pair's
// terms once into slot k, and both agents read them back in the order of a whole neighbour list sorted by
// that order, the other one negated: first the pairs earlier agents own (mirrored(i), by owner), then its
// own. So every agent's sum runs over the same values in the same order whatever the thread count, and
// equals the sum over its whole list (tests/sim/flock_neighbor_forces_test.cpp).
// Built by a counting sort over the pairs (serial, O(pairs), no search); nothing allocated once grown.
#include <span>
#include <vector>

#include "sim/flock/neighbor_lists.h"

namespace kf {

class PairIndex {
 public:
  // owned: lists from NeighborGrid::search_owned.
  void build(const NeighborLists& owned);

  int pairs() const { return int(slot_.size()); }
  // Slots of the pairs agent i is the later agent of, in its owners' order.
  std::span<const int> mirrored(int i) const {
    return {slot_.data() + start_[i], std::size_t(start_[i + 1] - start_[i])};
  }

 private:
  std::vector<int> start_;  // p + 1
  std::vector<int> slot_;   // pairs
};

}  // namespace kf
