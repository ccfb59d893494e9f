#pragma once
// Fixed-radius neighbour lists for agents on the ground plane, by a hashed uniform grid.
//
// Cells are radius / kReach wide in x and z, so a (2 kReach + 1)^2 block of cells holds every neighbour
// (smaller cells than the radius: fewer agents tested for each one found), and are mapped into a table of
// ~4p buckets (a flock at the figures' density fits its box unwrapped) filled by a counting sort, so
// memory is linear in agents however far the flock spreads. The table is the flock's bounding box of
// cells in row order, wrapped when the box has more cells than the table (cells sharing a bucket are then
// told apart by their indices), so each row of the block is, unwrapped, consecutive buckets: one
// contiguous run of agents. The agents' cells and x, z coordinates are copied in bucket order, so a run
// reads contiguous memory, and agents are visited in that order so nearby agents share cached cells. A
// neighbour list is ordered by cell (z, then x) and then by agent, whatever the table's shape. Cost is
// linear in agents at bounded density. After the first search with a given p nothing is allocated, except
// that work space and lists grow (amortised) if the flock becomes denser than ever before.
#include <cstdint>
#include <span>
#include <vector>

#include "core/types.h"
#include "sim/flock/neighbor_lists.h"

namespace kf {

class NeighborGrid {
 public:
  static constexpr int kReach = 2;  // cells per radius
  // x: 3p positions (m; y ignored). Afterwards out.neighbors(i) lists every j != i with
  // (x_i - x_j)^2 + (z_i - z_j)^2 < radius^2, in an order that depends only on x (not on the thread count).
  void search(const VecX& x, double radius, NeighborLists& out);

  // The same into the grid's own lists.
  void build(const VecX& x, double radius) { search(x, radius, lists_); }

  // Slot by slot, for passes that use each list at once and keep none: `index` sorts the agents at x into
  // slots (the table's bucket order), and `neighbors_of_slot` then writes the slots of one slot's
  // neighbours within `radius` into out (grown as needed), in the order search lists them, and returns how
  // many. A pass over agents' data packed in slot order then reads neighbours close together in memory.
  void index(const VecX& x, double radius);
  int agent_at(int slot) const { return sorted_[slot]; }
  int slot_of(int agent) const { return slot_of_agent_[agent]; }
  int neighbors_of_slot(int slot, std::vector<int>& out) const;
  const NeighborLists& lists() const { return lists_; }
  int agents() const { return lists_.agents(); }
  std::span<const int> neighbors(int i) const { return lists_.neighbors(i); }

 private:
  // The steps of search: work space for p agents, agents sorted by bucket, neighbours gathered per
  // agent into slabs, slabs compacted into the lists.
  void size_for(int p);
  // Origin and shape of the table for the cells of the agents (the bounding box when it fits).
  void fit_table(int p);
  void sort_into_buckets(const VecX& x, double radius, int p);
  void gather_into_slabs(int p);
  void compact_slabs(int p, NeighborLists& out) const;

  uint64_t bucket_of(int64_t cx, int64_t cz) const {
    return ((uint64_t(cz - origin_z_) & row_mask_) << row_shift_) | (uint64_t(cx - origin_x_) & column_mask_);
  }
  // Writes the slots of slot k's neighbours (up to `cap`; out has cap + 1 entries, the last scratch) to
  // out; returns how many it has.
  // kWrapped: the table is wrapped, so candidates' cells are checked.
  template <bool kWrapped>
  int gather(int k, double r2, int cap, int* out) const;
  // The agents of slots [s, e) in cell row cz and columns [cx0, cx0 + 2 kReach] within r2 of slot k, appended.
  template <bool kWrapped>
  int gather_run(int k, int s, int e, int64_t cx0, int64_t cz, double r2, int cap, int* out, int n) const;

  double r2_ = 0;                            // squared radius of the last index
  int buckets_ = 0;                          // a power of two, at least 16
  int64_t origin_x_ = 0, origin_z_ = 0;      // cell (origin_x_, origin_z_) is bucket 0
  uint64_t column_mask_ = 0, row_mask_ = 0;  // columns - 1, rows - 1 (columns x rows = buckets_)
  int row_shift_ = 0;                        // log2(columns)
  bool wrapped_ = false;                     // some bucket holds more than one cell of the box
  std::vector<int64_t> cell_x_, cell_z_;     // per agent
  std::vector<int> bucket_of_agent_;         // per agent
  std::vector<int> bucket_start_;            // buckets + 1
  std::vector<int> bucket_cursor_;           // buckets
  // Per slot of the bucket order: the agent, its cell and its x and z.
  std::vector<int> sorted_;
  std::vector<int> slot_of_agent_;  // its inverse
  std::vector<int64_t> sorted_cx_, sorted_cz_;
  std::vector<double> sorted_px_, sorted_pz_;
  std::vector<int> count_;  // neighbours per agent
  int capacity_ = 0;        // neighbours a slab holds
  std::vector<int> slab_;   // p slabs of capacity_ + 1 slots, compacted into the lists as agents
  NeighborLists lists_;
};

}  // namespace kf
