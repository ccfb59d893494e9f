#include "sim/flock/pair_index.h"

#include "core/check.h"

namespace kf {

void PairIndex::build(const NeighborLists& lists) {
  const int p = lists.agents();
  first_owned_.resize(p);
  owned_slot_.resize(p);
  cursor_.resize(p);
  mirror_.resize(lists.entries());
  for (int i = 0; i < p; ++i) cursor_[i] = lists.start(i);
  // Visiting owners in the lists' order, agent i's entries of earlier owners have all been matched when
  // its turn comes (cursor_[i] has passed them), and each of its own pairs (i, j) is the next unmatched
  // entry of j, since j's list is sorted by the same order.
  int slot = 0;
  for (int i : lists.order()) {
    first_owned_[i] = cursor_[i];
    owned_slot_[i] = slot;
    for (int e = cursor_[i], end = lists.start(i + 1); e < end; ++e) mirror_[cursor_[lists.entry(e)]++] = slot++;
  }
  pairs_ = slot;
  CHECK_EQ(2 * std::size_t(pairs_), std::size_t(lists.entries()));  // symmetric lists
}

}  // namespace kf
