// What the benches that time interleaved blocks in one process share (size_blocks, checkpoint):
// the still deposited bed they step, the thread's CPU clock, the quantiles of the per-round
// ratios and the plot of the CSV.
#pragma once

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "core/run/simulation.hpp"
#include "settled_drum.hpp"

namespace bench {

// This thread's CPU time in seconds: a block's cost without the time other processes took.
inline double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The deposited bed of n particles (settled_drum.hpp, deposited_packing: from DIR/cache, or
// deposited and loaded first), as bench/throughput's deposited section runs it (steel with e =
// 0.1 and mu_s = 0.5, dt = 1e-6 s) with the drum still, warmed by 50 steps.
inline std::unique_ptr<dem2d::Simulation> still_bed(
    std::int64_t n, const std::string& results,
    dem2d::SpatialSort sort = dem2d::SpatialSort::kAuto) {
  const Packing pk = deposited_packing(n, results + "/cache");
  dem2d::Scene scene = settled_scene(pk, 1.0e-6);
  scene.drum.speed = 0.0;  // the drum still, as deposited
  scene.run.spatial_sort = sort;
  auto sim = std::make_unique<dem2d::Simulation>(scene);
  for (int k = 0; k < 50; ++k) sim->step(/*end_observed=*/k + 1 == 50);
  return sim;
}

// The q-quantile of v (nearest rank; v not empty).
inline double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

// post/SCRIPT on the CSV at `path`, the PNG beside it; `more`: further arguments. Says what it
// wrote or that the script failed.
inline void plot_beside(const std::string& script, const std::string& path,
                        const std::string& more = "") {
  const std::string png = path.substr(0, path.rfind('.')) + ".png";
  const std::string cmd = "/usr/bin/python3 " DEM2D_SOURCE_DIR "/post/" + script + " '" + path +
                          "'" + more + " -o '" + png + "'";
  if (std::system(cmd.c_str()) != 0)
    std::printf("the plot script %s failed\n", script.c_str());
  else
    std::printf("wrote %s\n", png.c_str());
}

}  // namespace bench
