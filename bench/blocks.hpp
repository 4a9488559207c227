// What the benches that time interleaved blocks in one process share (sweep_modes, size_blocks):
// the thread's CPU clock and the quantiles of the per-round ratios.
#pragma once

#include <time.h>

#include <algorithm>
#include <vector>

namespace bench {

inline double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The q-quantile of v (nearest rank; v not empty).
inline double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

}  // namespace bench
