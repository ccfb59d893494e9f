#pragma once
// Fixed-radius neighbour lists of p agents in one compressed array (CSR): agent i's neighbours are
// entries [start_i, start_{i+1}). Memory is 4 bytes per (agent, neighbour) entry plus 4 per agent, so
// lists grow with the neighbours actually found, not with the densest agent's count. Filled by
// NeighborGrid::search.
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
  // Heap bytes held (capacity, not size: what the lists really cost).
  std::size_t bytes() const { return (start_.capacity() + entries_.capacity()) * sizeof(int); }

 private:
  friend class NeighborGrid;
  std::vector<int> start_;  // p + 1
  std::vector<int> entries_;
};

}  // namespace kf
