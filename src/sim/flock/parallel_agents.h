#pragma once
// Runs f(i) for every agent i in [0, p), in parallel over blocks of agents with TBB.
//
// f must write only agent i's outputs, so the result is the same for any thread count. Small flocks
// run inline: a TBB launch costs more than their whole loop.
#include <tbb/parallel_for.h>

namespace kf {

template <class F>
void parallel_agents(int p, F&& f) {
  constexpr int kGrain = 128;
  if (p <= kGrain) {
    for (int i = 0; i < p; ++i) f(i);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, p, kGrain), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i < r.end(); ++i) f(i);
  });
}

}  // namespace kf
