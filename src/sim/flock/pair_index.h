#pragma once
// Each neighbour pair once: of a pair's two list entries, the agent earlier in the lists' order
// (NeighborLists::order) owns the pair. Its terms are computed once, into the owner's slot, and both agents
// read them back in their own list order (the other one negated), so every agent's sum runs over the same
// values in the same order as a pass over its whole list, on any thread count.
//
// Each list is sorted by that order, so agent i's entries owned by an earlier agent come first, [start_i,
// first_owned(i)), and the pairs it owns follow; slots are numbered owner by owner in that order. Built in one
// serial pass over the entries (no search): O(entries), nothing allocated once the buffers have grown.
#include <vector>

#include "sim/flock/neighbor_lists.h"

namespace kf {

class PairIndex {
 public:
  void build(const NeighborLists& lists);

  int pairs() const { return pairs_; }
  // Agent i's first entry that it owns; the entries before it (from lists.start(i)) are owned by others.
  int first_owned(int i) const { return first_owned_[i]; }
  // Slot of agent i's first owned pair; the pair of its owned entry e is owned_slot(i) + e - first_owned(i).
  int owned_slot(int i) const { return owned_slot_[i]; }
  // Slot of the pair of entry e, for an entry its agent does not own.
  int mirror(int e) const { return mirror_[e]; }

 private:
  int pairs_ = 0;
  std::vector<int> first_owned_, owned_slot_;  // p
  std::vector<int> mirror_;                    // entries (those before first_owned of their agent)
  std::vector<int> cursor_;                    // p: next entry of an agent still to be matched
};

}  // namespace kf
