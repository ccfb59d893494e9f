#pragma once
// An optimisation's memory, estimated before it runs: the rollout's states and tape (what checkpointing
// trades for recomputation) and the optimiser's vectors. Used to switch checkpointing on when keeping every
// step would pass a budget, and to refuse a run that cannot fit at all.
#include <cstddef>

#include "sim/system.h"

namespace kf {

struct MemoryEstimate {
  std::size_t base = 0;        // bytes that do not depend on the checkpoint spacing (optimiser, controls)
  std::size_t per_state = 0;   // one kept state: x and v (bytes)
  std::size_t per_record = 0;  // one tape entry (System::record_bytes_estimate)
  int steps = 0;               // N
  int extra_kept = 0;          // states kept besides the checkpoints when checkpointed (those a cost reads)

  // Estimated bytes with checkpoint spacing `every` (0: every state and tape entry kept):
  //   stored:        base + (N + 1) states + N entries
  //   checkpointed:  base + (ceil(N/k) + 2 + extra) kept states, each with a step context counted as half a
  //                  state, + (k + 3) states and k + 1 entries of work space (segment buffer, scratch).
  std::size_t bytes(int every) const;
};

// The rollout part (base 0) of `steps` steps of `sys`; extra_kept as above.
MemoryEstimate estimate_rollout_memory(const System& sys, int steps, int extra_kept);

// Bytes of the vectors an L-BFGS optimisation over `variables` doubles holds with `lbfgs_memory` pairs
// of history: NLopt's LD_LBFGS keeps 2m + 4 vectors, the problem and driver about 8 more (controls,
// gradient, effort gradient, best point, trial point, ...).
std::size_t optimizer_bytes(std::size_t variables, int lbfgs_memory);

// Checkpoint spacing for a budget (bytes): 0 when keeping everything fits; otherwise the spacing with the
// smallest estimate (about sqrt(N)). Sets `fits` to whether the returned spacing's estimate is within it.
int checkpoint_spacing_for(const MemoryEstimate& e, std::size_t budget, bool& fits);

// Physical memory of this machine (bytes; 0 when unknown), and the default budget of a run: half of it,
// or 8 GB when unknown.
std::size_t physical_memory_bytes();
std::size_t default_memory_budget();
// What this process holds in memory now (bytes; 0 when unknown): code, libraries, the scene, work space,
// which a run's budget must leave room for besides what it plans.
std::size_t resident_bytes();

}  // namespace kf
