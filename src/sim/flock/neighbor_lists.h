#pragma once
// Fixed-radius neighbour lists of p agents in one compressed array (CSR): agent i's neighbours are
// entries [start_i, start_{i+1}). Memory is 4 bytes per (agent, neighbour) entry plus 8 per agent, so a
// tape of these grows with the neighbours actually found, not with the densest agent's count. Filled by
// NeighborGrid::search.
//
// Every list is sorted by one order of all agents (order(): the agents in that order), so a pair's two
// entries can be matched up in one pass (PairIndex) and each pair's terms computed once.
#include <cstddef>
#include <span>
#include <vector>

namespace kf {

class NeighborLists {
 public:
  int agents() const { return start_.empty() ? 0 : int(start_.size()) - 1; }
  std::span<const int> neighbors(int i) const {
    return {entries_.data() + start_[i], size_t(start_[i + 1] - start_[i])};
  }
  // Index of agent i's first entry (start(agents()) = entries()), and the agent of entry e.
  int start(int i) const { return start_[i]; }
  int entry(int e) const { return entries_[e]; }
  // Neighbour entries over all agents (each pair counted from both sides).
  int entries() const { return start_.empty() ? 0 : start_.back(); }
  // All agents in the order every list is sorted by.
  std::span<const int> order() const { return order_; }
  // Heap bytes held (capacity, not size: what a tape of these really costs).
  std::size_t bytes() const { return (start_.capacity() + entries_.capacity() + order_.capacity()) * sizeof(int); }

 private:
  friend class NeighborGrid;
  std::vector<int> start_;  // p + 1
  std::vector<int> entries_;
  std::vector<int> order_;  // p
};

}  // namespace kf
