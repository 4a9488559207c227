// bm_kernels: Google Benchmark timings of the three kernels of a step on a settled drum of
// 10 000 polydisperse steel spheres (bench/settled_drum.hpp: r 6-10 mm, 1.44 m circular drum,
// fill 0.31, dt = 1e-6 s), for each contact law (hertz-mindlin, thesis, linear) with the epsd
// rolling model and with none, to show that a model a scene does not use costs nothing:
//   BM_Forces  Simulation::refresh_forces(): the pair loop over the neighbour list and the wall
//              contacts, plus the accelerations (no state change: dt = 0).
//   BM_Rebuild Simulation::rebuild(): cell grid, Verlet lists of particle pairs and of wall
//              contacts, in canonical order, with the contact histories carried over. It does
//              not depend on the contact law (timed for each only as a check).
//   BM_Step    Simulation::step() with velocity Verlet: drift, rebuild when needed, forces,
//              kick, history commit, stability check (the drum turns; the charge evolves).
// The particles start from one shared state: the settled and loaded packing (cached in
// bench/results/cache/settled_drum_10000.csv, made on first use in about a minute) after 500
// steps of hertz-mindlin + epsd with the drum turning, so every model sees the same contacts.
// Counters: N particles, contacts (at the end) and candidate pairs; per_particle is the time per
// iteration divided by N (CPU time); items_per_second counts particles. The Time and CPU columns
// differ only when the machine is shared: read CPU. ("Library was built as DEBUG" in the header
// refers to the system's Google Benchmark library, not to dem2d.)
//
//   build/bench/bm_kernels [--benchmark_filter=Forces] [--benchmark_repetitions=3]
//                          [--benchmark_out=bench/results/bm_kernels.json
//                          --benchmark_out_format=json]
#include <benchmark/benchmark.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/run/simulation.hpp"
#include "settled_drum.hpp"

namespace {

using dem2d::ContactModelKind;
using dem2d::RollingModelKind;
using dem2d::Simulation;

constexpr std::int64_t kParticles = 10000;
constexpr double kDt = 1.0e-6;

struct ModelCase {
  ContactModelKind model;
  RollingModelKind rolling;
};

// The settled charge after 500 steps of the default model: positions, velocities and spins.
const dem2d::Scene& loaded_scene() {
  static const dem2d::Scene scene = [] {
    std::fprintf(stderr, "bm_kernels: preparing the settled %lld-particle drum ...\n",
                 static_cast<long long>(kParticles));
    const bench::Packing pk =
        bench::settled_packing(kParticles, DEM2D_SOURCE_DIR "/bench/results/cache", false);
    dem2d::Scene s = bench::settled_scene(pk, kDt);
    Simulation sim(s);
    for (int k = 0; k < 500; ++k) sim.step();
    const dem2d::ParticleStore& p = sim.particles();
    for (std::size_t k = 0; k < p.n_owned(); ++k) {
      // Particles are matched by id: the store may have been reordered.
      dem2d::ParticleSpec& q = s.particles[static_cast<std::size_t>(p.id[k])];
      q.position = p.pos[k];
      q.velocity = p.vel[k];
      q.spin = p.omega[k];
    }
    std::fprintf(stderr, "bm_kernels: %lld contacts after 500 steps\n",
                 static_cast<long long>(sim.last_totals().contacts));
    return s;
  }();
  return scene;
}

std::unique_ptr<Simulation> make_simulation(const ModelCase& c) {
  dem2d::Scene s = loaded_scene();
  s.contact.model = c.model;
  s.contact.rolling = c.rolling;
  return std::make_unique<Simulation>(s);
}

void set_counters(benchmark::State& state, const Simulation& sim) {
  const double n = static_cast<double>(sim.particles().n_owned());
  state.counters["N"] = n;
  state.counters["contacts"] = static_cast<double>(sim.last_totals().contacts);
  state.counters["pairs"] = static_cast<double>(sim.pairs().size());
  // Seconds per particle (the time of an iteration over N), printed with an SI prefix: "88ns".
  state.counters["per_particle"] = benchmark::Counter(
      n, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(n));
}

void BM_Forces(benchmark::State& state, ModelCase c) {
  auto sim = make_simulation(c);
  for (auto _ : state) sim->refresh_forces();
  set_counters(state, *sim);
}

void BM_Rebuild(benchmark::State& state, ModelCase c) {
  auto sim = make_simulation(c);
  for (auto _ : state) sim->rebuild();
  set_counters(state, *sim);
}

void BM_Step(benchmark::State& state, ModelCase c) {
  auto sim = make_simulation(c);
  try {
    for (auto _ : state) sim->step();
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  set_counters(state, *sim);
  state.counters["rebuilds"] = static_cast<double>(sim->neighbor_builds());
}

constexpr ModelCase kHertzEpsd{ContactModelKind::kHertzMindlin, RollingModelKind::kEpsd};
constexpr ModelCase kHertzNone{ContactModelKind::kHertzMindlin, RollingModelKind::kNone};
constexpr ModelCase kThesisEpsd{ContactModelKind::kThesis, RollingModelKind::kEpsd};
constexpr ModelCase kThesisNone{ContactModelKind::kThesis, RollingModelKind::kNone};
constexpr ModelCase kLinearEpsd{ContactModelKind::kLinear, RollingModelKind::kEpsd};
constexpr ModelCase kLinearNone{ContactModelKind::kLinear, RollingModelKind::kNone};

#define DEM2D_KERNEL(fn)                                                                \
  BENCHMARK_CAPTURE(fn, hertz_mindlin_epsd, kHertzEpsd)->Unit(benchmark::kMicrosecond); \
  BENCHMARK_CAPTURE(fn, hertz_mindlin_none, kHertzNone)->Unit(benchmark::kMicrosecond); \
  BENCHMARK_CAPTURE(fn, thesis_epsd, kThesisEpsd)->Unit(benchmark::kMicrosecond);       \
  BENCHMARK_CAPTURE(fn, thesis_none, kThesisNone)->Unit(benchmark::kMicrosecond);       \
  BENCHMARK_CAPTURE(fn, linear_epsd, kLinearEpsd)->Unit(benchmark::kMicrosecond);       \
  BENCHMARK_CAPTURE(fn, linear_none, kLinearNone)->Unit(benchmark::kMicrosecond)

DEM2D_KERNEL(BM_Forces);
DEM2D_KERNEL(BM_Rebuild);
DEM2D_KERNEL(BM_Step);

}  // namespace
