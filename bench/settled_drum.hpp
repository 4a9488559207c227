// settled_drum.hpp: settled charges of polydisperse steel spheres in a circular drum, shared by
// bench/throughput.cpp, bench/strong_scaling.cpp and bench/bm_kernels.cpp (header only:
// bench/CMakeLists.txt builds each bench/*.cpp as its own program).
//
// The drum charge: N steel spheres (thesis steel: rho 7800, E 2e11 Pa, G 8e10 Pa, e = 0.73,
// mu_s = 0.1, mu_r = 0.05), radius uniform in [6, 10] mm, in a circular drum (sides = 0) of
// radius R(N) = 2.5 m sqrt(N / 30 000) (fill fraction 0.31 at every N) turning at
// 1.5 rad/s sqrt(2.5 m / R) (Froude number 0.57 at every N). N = 30 000 is the 2.5 m drum at
// 1.5 rad/s. Contact law hertz-mindlin with epsd rolling resistance.
//
// How each size is made.
// N < 300 000 (1e3, 3e3, 1e4, 3e4, 1e5): settled by dynamics (settle_packing), in three stages,
// all with the drum still:
//  1. The core's fill (region "bottom": a loose hexagonal lattice, seed 1) falls and settles in
//     a soft copy of the steel (e = 0.1, mu_s = 0.3, E and G scaled by 1e-3 sqrt(N / 1000),
//     i.e. in proportion to the bed depth, so that the overlaps (static and at the impacts of
//     the collapsing lattice) are about the same few % of a radius in every drum) at half the
//     core's limit dt for that material, until the mean speed sqrt(2 KE / M) is below 2 cm/s
//     (at least 0.4 s, at most 1.0 s of simulated time).
//  2. Those overlaps would explode in steel (its contacts push 100-1000 times harder at the same
//     overlap), so they are removed geometrically: Gauss-Seidel sweeps over the neighbour pairs
//     with over-relaxation (omega = 1.8) push overlapping pairs apart (a wall overlap is
//     removed fully; no single push above a tenth of the allowed travel) until no overlap above
//     1e-8 m is left; the candidate pairs are rebuilt whenever a particle has moved a quarter
//     of the skin. Any rest is removed by shrinking radii by at most half of it (normally
//     < 1e-8 m; more than 1e-6 m is an error). The charge grows by a few mm at the top, the
//     over-relaxation leaves small gaps, and the velocities are set to zero.
//  3. Steel, at dt = 1e-6 s: gravity closes the gaps and loads the contacts (~5-10 ms). It runs
//     in chunks of 1000 steps until the number of contacts grows by less than 1 % in a chunk
//     (at least 3000, at most 20 000 steps).
// N >= 300 000 (3e5, 1e6): settling by dynamics would take hours (a 1e6 soft settle was stopped
// after 40 minutes of one core at 0.3 s of its at least 0.4 s, 2026-11-26), so
// the bed is deposited and loaded (deposit_packing, deposited_packing; bench/throughput's
// "deposited" section builds the smaller sizes the same way, to compare like with like):
//  1. Deposition (bench/deposition.hpp): N discs, radii uniform in [6, 10] mm, dropped one by
//     one into the drum of radius R(N) and rolled, frictionless and quasi-static, into a pocket
//     of two supports (discs or the wall), touching them at zero overlap; of 4 pseudo-random drop
//     points per disc the lowest landing is taken, so that the bed grows in flat layers. Ids in
//     the fill's order (fill_order). 2 s for 1e6 discs; 1.99 touching pairs per disc; largest
//     overlap 3e-12 m (rounding).
//  2. Loading, drum still, at dt = 1e-6 s in deposited_material() (steel with e = 0.1 and
//     mu_s = 0.5), in chunks of 1000 steps until the contacts grow by less than 1 % in a chunk
//     and the mean speed sqrt(2 KE / M) is below 5 cm/s (at least 3, at most 80 chunks): 30 000
//     spheres reach 1.89 contacts per particle in 9 000 steps, 1e5 in 14 000. (The deeper the
//     bed, the longer its weight takes to come on: at 1e6 the mean speed was still rising
//     through 0.15 m/s after 25 000 steps, with 1.69 contacts per particle.)
// The thesis steel (e = 0.73, mu_s = 0.1) cannot hold a deposited bed: its loose layers keep
// closing up (30 000: 1.89 contacts per particle after loading, 1.47 after 1 000 more steps, 0.19
// after 4 500 steps in the turning drum), so deposited beds are measured in deposited_material()
// (settled_scene), which costs the same per contact: the law is the same code, only two
// coefficients differ. Before this (until 2026-11-26) the large sizes were tiled from copies of a
// patch of the settled 30 000 packing (the tiling is now bench/partition's own, which needs
// positions only); the seams between copies left voids, and loading that bed was tried three
// ways without success (only 0.5 contacts per particle at 1e6; the soft settle above).
//
// The size-ratio charges (settle_ratio_packing, bench/throughput's "ratios" section): N spheres
// of the same steel with radii log-uniform between r_max / ratio and r_max = 10 mm (the
// deterministic quantiles r_k = r_max ratio^(-(k + 1/2) / N), k = 0 .. N-1: equal numbers per
// factor of radius; ratio 1: every radius exactly 10 mm, the monodisperse reference), in a
// circular drum of radius sqrt(sum r^2 / 0.31) (fill fraction 0.31 as above) turning at
// 1.5 rad/s sqrt(2.5 m / R). The fill's lattice (spacing 2.1 r_max) cannot hold a 10:1 charge
// at this fill fraction, so stage 1 starts instead from a random sequential placement (largest
// first, no overlaps, fixed pseudo-random sequence) in the bottom segment of the drum whose
// area is the charge's area / 0.4, ids in the fill's order as above. Then stages 1-3, with the
// soft stiffness scaled by the bed depth and by the size ratio (E x 1e-3 ratio R / R(1000): a
// small sphere wedged between large ones overlaps more, relative to its radius, than in a
// monodisperse bed; at 1e-3 R / R(1000) alone the 5:1 and 10:1 beds passed the core's 25 %
// overlap guard, as ratio^(4/3) predicts) and stage 3 at dt = 5e-7 s (steel
// spheres of 1 mm: the core's limit dt is about 5.3e-7 s); the measured runs use 5e-7 s too.
//
// Positions, velocities (a few cm/s) and spins are cached in DIR/settled_drum_<N>.csv and
// DIR/settled_ratio<ratio>_<N>.csv (x, y, radius, vx, vy, spin; the first line says how the
// packing was made), as settling 1e5 particles takes several minutes: delete a file to make it
// again. The measured runs (settled_scene) start from it with the drum turning at full speed;
// the benches run untimed steps first.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/base/scene.hpp"
#include "core/run/simulation.hpp"
#include "deposition.hpp"

namespace bench {

constexpr double kRadiusMin = 0.006, kRadiusMax = 0.010;  // m
constexpr double kRefN = 30000.0, kRefDrum = 2.5, kRefSpeed = 1.5;
constexpr const char* kCacheVersion = "settled_drum v7";  // bump when the recipe changes
constexpr const char* kRatioCacheVersion = "settled_drum ratio v1";
constexpr const char* kDepositCacheVersion = "deposited_drum v2";
constexpr std::int64_t kDepositFrom = 300000;  // settled_packing: N >= this deposited
constexpr int kDepositLoadChunks = 80;         // of 1000 steps, at most
constexpr double kDepositLoadedSpeed = 0.05;   // m/s: loaded when the mean speed is below
constexpr double kFillFraction = 0.31;         // charge area / drum area
constexpr double kRatioDt = 5.0e-7;            // s: every size-ratio run (1 mm steel spheres)

inline double drum_radius_for(std::int64_t n) {
  return kRefDrum * std::sqrt(static_cast<double>(n) / kRefN);
}
inline double drum_speed_for(double radius) { return kRefSpeed * std::sqrt(kRefDrum / radius); }
// Stiffness of the stage-1 material relative to steel, in proportion to the bed depth.
inline double soft_factor_for(std::int64_t n) {
  return 1.0e-3 * std::sqrt(static_cast<double>(n) / 1000.0);
}

inline dem2d::MaterialSpec steel(double stiffness_factor = 1.0) {
  dem2d::MaterialSpec m;
  m.name = "steel";
  m.density = 7800.0;
  m.youngs_modulus = 2.0e11 * stiffness_factor;
  m.shear_modulus = 8.0e10 * stiffness_factor;
  m.poisson_ratio = m.youngs_modulus / (2.0 * m.shear_modulus) - 1.0;
  m.restitution = 0.73;
  m.sliding_friction = 0.1;
  m.rolling_friction = 0.05;
  return m;
}

// The softened, well-damped material of stage 1.
inline dem2d::MaterialSpec settling_material(double stiffness_factor) {
  dem2d::MaterialSpec m = steel(stiffness_factor);
  m.restitution = 0.1;
  m.sliding_friction = 0.3;
  return m;
}

// The circular drum with no particles yet; the caller adds materials and particles.
inline dem2d::Scene drum_scene(double radius, double speed) {
  dem2d::Scene s;
  s.title = "bench: polydisperse steel in a circular drum";
  s.deck_path = "bench(settled_drum)";
  s.contact.model = dem2d::ContactModelKind::kHertzMindlin;
  s.contact.rolling = dem2d::RollingModelKind::kEpsd;
  s.drum.present = true;
  s.drum.radius = radius;
  s.drum.speed = speed;
  s.drum.ramp_time = 0.0;
  s.drum.sides = 0;
  s.drum.material = "steel";
  s.run.duration = 1.0;
  return s;
}

struct Packing {
  std::vector<dem2d::Vec2> pos;
  std::vector<double> radius;
  std::vector<dem2d::Vec2> vel;
  std::vector<double> spin;
  bool from_cache = false;
  double settle_wall = 0.0;            // s of wall time spent settling (0 when read from the cache)
  double settle_time = 0.0;            // s of simulated time of stage 1
  double residual_overlap = 0.0;       // m, largest overlap left after stage 2
  int relax_rounds = 0;                // candidate-pair rebuilds of stage 2
  std::int64_t load_steps = 0;         // steps of stage 3
  double contacts_per_particle = 0.0;  // at the end of stage 3
  double mean_speed = 0.0;             // m/s, sqrt(2 KE / M) at the end of stage 3
  bool deposited = false;              // deposit_packing: measured in deposited_material()
  double drum_radius = 0.0;            // m; 0: drum_radius_for(N)
  std::string recipe;                  // how it was made (the cache file's first line)
};

inline double drum_radius_of(const Packing& pk) {
  return pk.drum_radius > 0.0 ? pk.drum_radius
                              : drum_radius_for(static_cast<std::int64_t>(pk.pos.size()));
}

// Stage 2: remove the overlaps of the candidate pairs (local indices pi, pj) and with the drum
// wall (centred at the origin), by Gauss-Seidel sweeps with over-relaxation. Sweeps run until
// the largest overlap is below `tol` (returns true) or until some particle has moved
// `max_move` from where it started, as the candidate pairs are then out of date (returns
// false: rebuild them and call again). `worst` is the largest overlap of the last sweep.
inline bool relax_overlaps(std::vector<dem2d::Vec2>& x, const std::vector<double>& r,
                           double drum_radius, const std::vector<std::int32_t>& pi,
                           const std::vector<std::int32_t>& pj, double max_move, double& worst,
                           double tol = 1e-8, double omega = 1.8) {
  const std::vector<dem2d::Vec2> x0 = x;
  // No single push exceeds a tenth of max_move, so no particle can pass through a neighbour
  // that is not in the candidate list before the displacement check ends the round.
  const double max_push = 0.1 * max_move;
  for (int sweep = 0; sweep < 100000; ++sweep) {
    worst = 0.0;
    for (std::size_t k = 0; k < x.size(); ++k) {
      const double d = dem2d::norm(x[k]);
      const double ov = d + r[k] - drum_radius;
      if (ov > 0.0) {
        x[k] = ((d - std::min(ov, max_push)) / d) * x[k];
        worst = std::max(worst, ov);
      }
    }
    for (std::size_t k = 0; k < pi.size(); ++k) {
      const std::int32_t i = pi[k], j = pj[k];
      const dem2d::Vec2 d = x[j] - x[i];
      const double dist = dem2d::norm(d);
      const double ov = r[i] + r[j] - dist;
      if (ov > 0.0) {
        const dem2d::Vec2 push = (std::min(0.5 * omega * ov, max_push) / dist) * d;
        x[i] -= push;
        x[j] += push;
        worst = std::max(worst, ov);
      }
    }
    if (worst < tol) return true;
    double moved2 = 0.0;
    for (std::size_t k = 0; k < x.size(); ++k)
      moved2 = std::max(moved2, dem2d::norm2(x[k] - x0[k]));
    if (moved2 > max_move * max_move) return false;
  }
  return false;
}

// The material of a deposited bed (deposit_packing), loaded and measured in it: steel, well
// damped (e = 0.1) and with friction 0.5. It holds the bed: in the thesis steel (e = 0.73,
// mu_s = 0.1) a deposited bed does not stay put, it keeps compacting (30 000 spheres: 1.89
// contacts per particle after loading, 1.47 after 1000 more steps in the thesis steel with the
// drum still and 0.19 after the throughput run's 4 500 steps with it turning, the particles
// falling as the loose layers of the deposition close up).
inline dem2d::MaterialSpec deposited_material() {
  dem2d::MaterialSpec m = steel(1.0);
  m.restitution = 0.1;
  m.sliding_friction = 0.5;
  return m;
}

// A scene of the packing's particles (with their velocities) in `material`, dt given.
inline dem2d::Scene packing_scene(const Packing& pk, const dem2d::MaterialSpec& material,
                                  double drum_speed, double dt) {
  const double radius = drum_radius_of(pk);
  dem2d::Scene s = drum_scene(radius, drum_speed);
  s.materials = {material};
  s.particles.resize(pk.pos.size());
  for (std::size_t k = 0; k < pk.pos.size(); ++k) {
    s.particles[k].material = material.name;
    s.particles[k].radius = pk.radius[k];
    s.particles[k].position = pk.pos[k];
    if (k < pk.vel.size()) s.particles[k].velocity = pk.vel[k];
    if (k < pk.spin.size()) s.particles[k].spin = pk.spin[k];
  }
  s.run.dt = dt;
  s.run.dt_auto = false;
  return s;
}

// The measured scene: steel (a deposited bed: deposited_material()), the drum turning at its full
// speed from t = 0.
inline dem2d::Scene settled_scene(const Packing& pk, double dt) {
  const double radius = drum_radius_of(pk);
  return packing_scene(pk, pk.deposited ? deposited_material() : steel(1.0), drum_speed_for(radius),
                       dt);
}

// Copy the state of a simulation back into the packing (ids follow the particle list).
inline void take_state(const dem2d::Simulation& sim, Packing& pk) {
  const dem2d::ParticleStore& q = sim.particles();
  pk.pos.resize(q.n_owned());
  pk.radius.resize(q.n_owned());
  pk.vel.resize(q.n_owned());
  pk.spin.resize(q.n_owned());
  for (std::size_t k = 0; k < q.n_owned(); ++k) {
    const auto id = static_cast<std::size_t>(q.id[k]);
    pk.pos[id] = q.pos[k];
    pk.radius[id] = q.radius[k];
    pk.vel[id] = q.vel[k];
    pk.spin[id] = q.omega[k];
  }
}

// Half of the core's limit dt for a scene (the limit is 0.5 min(Rayleigh time, Hertz time)).
inline double half_limit_dt(dem2d::Scene s) {
  s.run.allow_unsafe_dt = true;
  const dem2d::Simulation probe(s);
  return 0.5 * probe.scales().limit_dt;
}

// Stage 2: the overlaps of `out` (the state of `sim`'s particles, indexed by id) removed
// geometrically; `sim` gives the candidate pairs (any material: only its lists are used).
inline void remove_overlaps(dem2d::Simulation& sim, Packing& out, double radius) {
  dem2d::ParticleStore& store = sim.particles();
  bool relaxed = false;
  double worst = 0.0;
  for (int round = 0; round < 2000 && !relaxed; ++round) {
    for (std::size_t k = 0; k < store.n_owned(); ++k)
      store.pos[k] = out.pos[static_cast<std::size_t>(store.id[k])];
    sim.rebuild();
    std::vector<std::int32_t> pi(sim.pairs().i.begin(), sim.pairs().i.end()),
        pj(sim.pairs().j.begin(), sim.pairs().j.end());
    for (auto& v : pi) v = static_cast<std::int32_t>(store.id[static_cast<std::size_t>(v)]);
    for (auto& v : pj) v = static_cast<std::int32_t>(store.id[static_cast<std::size_t>(v)]);
    relaxed = relax_overlaps(out.pos, out.radius, radius, pi, pj, 0.25 * sim.skin(), worst);
    out.relax_rounds = round + 1;
  }
  if (!relaxed)
    throw std::runtime_error("settled_drum: the soft overlaps could not be removed (" +
                             std::to_string(worst) + " m left after " +
                             std::to_string(out.relax_rounds) + " rounds)");
  // Whatever is left is removed by shrinking radii: each particle by half of its largest pair
  // overlap plus its wall overlap.
  for (std::size_t k = 0; k < store.n_owned(); ++k)
    store.pos[k] = out.pos[static_cast<std::size_t>(store.id[k])];
  sim.rebuild();
  std::vector<double> shrink(out.pos.size(), 0.0);
  for (std::size_t k = 0; k < sim.pairs().size(); ++k) {
    const auto i = static_cast<std::size_t>(store.id[static_cast<std::size_t>(sim.pairs().i[k])]);
    const auto j = static_cast<std::size_t>(store.id[static_cast<std::size_t>(sim.pairs().j[k])]);
    const double ov = out.radius[i] + out.radius[j] - dem2d::norm(out.pos[j] - out.pos[i]);
    out.residual_overlap = std::max(out.residual_overlap, ov);
    shrink[i] = std::max(shrink[i], 0.5 * ov);
    shrink[j] = std::max(shrink[j], 0.5 * ov);
  }
  for (std::size_t k = 0; k < out.pos.size(); ++k) {
    const double wall = std::max(0.0, dem2d::norm(out.pos[k]) + out.radius[k] - radius);
    out.residual_overlap = std::max(out.residual_overlap, wall);
    out.radius[k] -= shrink[k] + wall;
  }
  if (out.residual_overlap > 1e-6)
    throw std::runtime_error("settled_drum: an overlap of " + std::to_string(out.residual_overlap) +
                             " m is left after the relaxation");
  std::fill(out.vel.begin(), out.vel.end(), dem2d::Vec2{});
  std::fill(out.spin.begin(), out.spin.end(), 0.0);
}

// Stage 3: steel at `dt` with the drum still, in chunks of 1000 steps until the contacts grow by
// less than 1 % in a chunk and the mean speed is below `max_speed` (at least 3 chunks, at most
// `max_chunks`).
inline void load_in_steel(Packing& out, double dt, int max_chunks = 20,
                          const dem2d::MaterialSpec& material = steel(1.0),
                          double max_speed = std::numeric_limits<double>::infinity()) {
  dem2d::Simulation steel_sim(packing_scene(out, material, 0.0, dt));
  double mass = 0.0;
  for (std::size_t k = 0; k < steel_sim.particles().n_owned(); ++k)
    mass += steel_sim.particles().mass[k];
  double contacts = 0.0;
  for (int chunk = 0; chunk < max_chunks; ++chunk) {
    for (int k = 0; k < 1000; ++k) steel_sim.step();
    const double c = static_cast<double>(steel_sim.last_totals().contacts);
    out.mean_speed = std::sqrt(2.0 * steel_sim.diagnostics().kinetic_energy / mass);
    std::fprintf(stderr,
                 "   stage 3: %lld steps, %.3g contacts per particle, mean speed %.3g m/s\n",
                 static_cast<long long>(steel_sim.step_count()),
                 c / static_cast<double>(out.pos.size()), out.mean_speed);
    const bool flat = c < 1.01 * contacts;
    contacts = c;
    if (chunk >= 2 && flat && out.mean_speed < max_speed) break;
  }
  out.load_steps = steel_sim.step_count();
  out.contacts_per_particle = contacts / static_cast<double>(out.pos.size());
  take_state(steel_sim, out);
}

// Stages 1-3 from the scene of stage 1 (soft material, drum still, particles in place).
inline Packing settle_scene(dem2d::Scene s, double radius, double load_dt) {
  const auto t0 = std::chrono::steady_clock::now();
  Packing out;
  out.drum_radius = radius;
  s.run.dt = half_limit_dt(s);
  s.run.dt_auto = false;
  s.run.allow_unsafe_dt = true;
  dem2d::Simulation sim(s);
  double mass = 0.0;
  for (std::size_t k = 0; k < sim.particles().n_owned(); ++k) mass += sim.particles().mass[k];
  while (true) {
    sim.run_until(sim.time() + 0.05);
    const double v = std::sqrt(2.0 * sim.diagnostics().kinetic_energy / mass);
    std::fprintf(stderr,
                 "   stage 1: t = %.2f s, mean speed %.4f m/s, %.3g contacts per particle\n",
                 sim.time(), v,
                 static_cast<double>(sim.last_totals().contacts) /
                     static_cast<double>(sim.particles().n_owned()));
    if ((sim.time() >= 0.4 && v < 0.02) || sim.time() >= 1.0) break;
  }
  out.settle_time = sim.time();
  take_state(sim, out);
  remove_overlaps(sim, out, radius);
  load_in_steel(out, load_dt);
  out.settle_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

inline Packing settle_packing(std::int64_t n) {
  const double radius = drum_radius_for(n);
  // Stage 1: the soft fill falls and settles.
  dem2d::Scene s = drum_scene(radius, 0.0);
  s.materials = {settling_material(soft_factor_for(n))};
  dem2d::FillSpec fill;
  fill.material = "steel";
  fill.count = n;
  fill.radius_min = kRadiusMin;
  fill.radius_max = kRadiusMax;
  fill.region = dem2d::FillRegion::kBottom;
  s.fills = {fill};
  Packing out = settle_scene(s, radius, 1.0e-6);
  out.drum_radius = 0.0;  // drum_radius_for(n)
  return out;
}

// Uniform cell grid over a set of points (counting sort): neighbours() visits the 3 x 3 cells
// around a point.
class PointGrid {
 public:
  PointGrid(const std::vector<dem2d::Vec2>& x, double cell) : cell_(cell) {
    lo_ = {1e300, 1e300};
    dem2d::Vec2 hi{-1e300, -1e300};
    for (dem2d::Vec2 p : x) {
      lo_ = {std::min(lo_.x, p.x), std::min(lo_.y, p.y)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
    }
    nx_ = static_cast<int>((hi.x - lo_.x) / cell_) + 1;
    ny_ = static_cast<int>((hi.y - lo_.y) / cell_) + 1;
    start_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_) + 1, 0);
    for (dem2d::Vec2 p : x) ++start_[index(p) + 1];
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    items_.resize(x.size());
    std::vector<std::size_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < x.size(); ++i) items_[fill[index(x[i])]++] = i;
  }
  template <class F>
  void neighbours(dem2d::Vec2 p, F&& f) const {
    const int cx = cx_of(p), cy = cy_of(p);
    for (int y = std::max(0, cy - 1); y <= std::min(ny_ - 1, cy + 1); ++y)
      for (int x = std::max(0, cx - 1); x <= std::min(nx_ - 1, cx + 1); ++x) {
        const std::size_t c = static_cast<std::size_t>(y) * static_cast<std::size_t>(nx_) +
                              static_cast<std::size_t>(x);
        for (std::size_t k = start_[c]; k < start_[c + 1]; ++k) f(items_[k]);
      }
  }

 private:
  int cx_of(dem2d::Vec2 p) const {
    return std::clamp(static_cast<int>((p.x - lo_.x) / cell_), 0, nx_ - 1);
  }
  int cy_of(dem2d::Vec2 p) const {
    return std::clamp(static_cast<int>((p.y - lo_.y) / cell_), 0, ny_ - 1);
  }
  std::size_t index(dem2d::Vec2 p) const {
    return static_cast<std::size_t>(cy_of(p)) * static_cast<std::size_t>(nx_) +
           static_cast<std::size_t>(cx_of(p));
  }
  double cell_;
  dem2d::Vec2 lo_;
  int nx_ = 1, ny_ = 1;
  std::vector<std::size_t> start_, items_;
};

inline std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30U)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27U)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31U);
}

// The particles (pos, radius) reordered as the core's fill numbers them: rows of the fill's
// lattice pitch (2.1 r_max sqrt(3) / 2) from the bottom up, a fixed pseudo-random order within
// a row (the fill draws which sites of the last row it takes; the jitter mixes each row).
inline void fill_order(std::vector<dem2d::Vec2>& pos, std::vector<double>& radius) {
  const double pitch = 2.1 * kRadiusMax * std::sqrt(3.0) / 2.0;
  double y0 = 1e300;
  for (dem2d::Vec2 p : pos) y0 = std::min(y0, p.y);
  std::vector<std::pair<std::pair<std::int64_t, std::uint64_t>, std::size_t>> key(pos.size());
  for (std::size_t k = 0; k < pos.size(); ++k)
    key[k] = {{static_cast<std::int64_t>((pos[k].y - y0) / pitch), splitmix64(k)}, k};
  std::sort(key.begin(), key.end());
  std::vector<dem2d::Vec2> p2(pos.size());
  std::vector<double> r2(pos.size());
  for (std::size_t k = 0; k < key.size(); ++k) {
    p2[k] = pos[key[k].second];
    r2[k] = radius[key[k].second];
  }
  pos.swap(p2);
  radius.swap(r2);
}

// The largest overlap between any two particles of a packing.
inline double largest_overlap(const std::vector<dem2d::Vec2>& x, const std::vector<double>& r) {
  const PointGrid grid(x, 2.0 * kRadiusMax);
  double worst = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i)
    grid.neighbours(x[i], [&](std::size_t j) {
      if (j > i) worst = std::max(worst, r[i] + r[j] - dem2d::norm(x[i] - x[j]));
    });
  return worst;
}

// The deposited charge of n particles (header: N >= 300 000): radii uniform in
// [kRadiusMin, kRadiusMax] and drop points from a fixed pseudo-random sequence; of `choices`
// drop points for each disc the one where it would first land lowest is taken, so that the bed
// grows in flat layers (dropped at uniformly random x, the shallow sides of a circular drum fill
// first and the bed turns into a V). Velocities and spins zero, not yet loaded.
inline Packing deposit_packing(std::int64_t n, int choices = 4) {
  const double R = drum_radius_for(n);
  Deposition d(R, kRadiusMax);
  std::uint64_t seq = 0;
  auto uniform = [&] { return static_cast<double>(splitmix64(seq++) >> 11U) * 0x1p-53; };
  for (std::int64_t k = 0; k < n; ++k) {
    const double r = kRadiusMin + (kRadiusMax - kRadiusMin) * uniform();
    double x = 0.0, low = std::numeric_limits<double>::infinity();
    bool tie = false;
    for (int c = 0; c < choices; ++c) {
      const double u = uniform(), xc = (R - r) * (2.0 * u - 1.0);
      const double y = d.landing(xc, r);
      if (y < low) {
        low = y;
        x = xc;
        tie = u < 0.5;
      }
    }
    d.drop(x, r, tie);
  }
  const std::int64_t rolls = d.rolls();
  Packing b;
  b.pos = d.positions();
  b.radius = d.radii();
  fill_order(b.pos, b.radius);
  b.vel.assign(b.pos.size(), dem2d::Vec2{});
  b.spin.assign(b.pos.size(), 0.0);
  b.deposited = true;
  // The deposition touches, never overlaps: anything above rounding is a bug, and in steel it
  // would fire the particles apart.
  double overlap = largest_overlap(b.pos, b.radius);
  for (std::size_t k = 0; k < b.pos.size(); ++k)
    overlap = std::max(overlap, dem2d::norm(b.pos[k]) + b.radius[k] - R);
  if (!(overlap < 1e-9))
    throw std::runtime_error("settled_drum: the deposition left an overlap of " +
                             std::to_string(overlap) + " m");
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "deposited (frictionless quasi-static rolling into two-support pockets, lowest of "
                "%d drop points per disc, %.3g rolls per disc; largest overlap %.3g m)",
                choices, static_cast<double>(rolls) / static_cast<double>(n), overlap);
  b.recipe = buf;
  return b;
}

// Size-ratio charges (header): the radii, r_max ratio^(-(k + 1/2) / n) for k = 0 .. n-1.
inline std::vector<double> ratio_radii(std::int64_t n, double ratio) {
  std::vector<double> r(static_cast<std::size_t>(n));
  for (std::size_t k = 0; k < r.size(); ++k)
    r[k] = kRadiusMax * std::pow(ratio, -(static_cast<double>(k) + 0.5) / static_cast<double>(n));
  return r;
}
inline double ratio_drum_radius(std::int64_t n, double ratio) {
  double area = 0.0;
  for (double r : ratio_radii(n, ratio)) area += r * r;
  return std::sqrt(area / kFillFraction);
}

// Area of the drum (radius R, centre 0) below the line y = c.
inline double area_below(double R, double c) {
  return R * R * (std::numbers::pi - std::acos(c / R)) + c * std::sqrt(R * R - c * c);
}

// Random sequential placement, largest first, of radii `r` (descending) in the segment of the
// drum below the line whose area is sum(pi r^2) / `fraction`; the line moves up by 1 % of R
// whenever 20 000 tries do not place a particle.
inline std::vector<dem2d::Vec2> loose_placement(const std::vector<double>& r, double R,
                                                double fraction = 0.4) {
  double area = 0.0;
  for (double v : r) area += std::numbers::pi * v * v;
  double lo = -R, hi = R;
  for (int it = 0; it < 100; ++it)
    (area_below(R, 0.5 * (lo + hi)) < area / fraction ? lo : hi) = 0.5 * (lo + hi);
  double top = hi;
  const double cell = 2.0 * kRadiusMax;
  const int nx = static_cast<int>(2.0 * R / cell) + 1;
  std::vector<std::vector<std::size_t>> cells(static_cast<std::size_t>(nx) *
                                              static_cast<std::size_t>(nx));
  auto cell_of = [&](double v) { return std::clamp(static_cast<int>((v + R) / cell), 0, nx - 1); };
  std::vector<dem2d::Vec2> pos(r.size());
  std::uint64_t draw = 0;
  auto uniform = [&]() {
    return static_cast<double>(splitmix64(draw++) >> 11U) * 0x1.0p-53;  // [0, 1)
  };
  for (std::size_t k = 0; k < r.size(); ++k) {
    for (int tries = 0;; ++tries) {
      if (tries == 20000) {
        top = std::min(R, top + 0.01 * R);
        tries = 0;
      }
      const dem2d::Vec2 p{-R + 2.0 * R * uniform(), -R + (top + R) * uniform()};
      if (dem2d::norm(p) + r[k] > R * (1.0 - 1e-6)) continue;
      bool clash = false;
      const int cx = cell_of(p.x), cy = cell_of(p.y);
      for (int y = std::max(0, cy - 1); y <= std::min(nx - 1, cy + 1) && !clash; ++y)
        for (int x = std::max(0, cx - 1); x <= std::min(nx - 1, cx + 1) && !clash; ++x)
          for (std::size_t j : cells[static_cast<std::size_t>(y * nx + x)])
            if (dem2d::norm(p - pos[j]) < r[k] + r[j]) {
              clash = true;
              break;
            }
      if (clash) continue;
      pos[k] = p;
      cells[static_cast<std::size_t>(cy * nx + cx)].push_back(k);
      break;
    }
  }
  return pos;
}

// A settled size-ratio charge (header), by dynamics.
inline Packing settle_ratio_packing(std::int64_t n, double ratio) {
  const double radius = ratio_drum_radius(n, ratio);
  std::vector<double> r = ratio_radii(n, ratio);  // descending
  std::vector<dem2d::Vec2> pos = loose_placement(r, radius);
  fill_order(pos, r);
  dem2d::Scene s = drum_scene(radius, 0.0);
  s.title = "bench: polydisperse steel, size ratio " + std::to_string(ratio);
  // Stiffness: the bed depth as for the drum, times the ratio (a 1 mm sphere wedged between
  // 10 mm ones overlapped by 25.5 % of its radius at 1x, beyond the core's 25 % guard).
  s.materials = {settling_material(1.0e-3 * radius / drum_radius_for(1000) * ratio)};
  s.particles.resize(pos.size());
  for (std::size_t k = 0; k < pos.size(); ++k) {
    s.particles[k].material = "steel";
    s.particles[k].radius = r[k];
    s.particles[k].position = pos[k];
  }
  return settle_scene(s, radius, kRatioDt);
}

inline void write_packing(const std::string& path, const std::string& header, const Packing& pk) {
  std::ofstream f(path);
  f << "# " << header << "\n";
  f << "x,y,radius,vx,vy,spin\n";
  char buf[256];
  for (std::size_t k = 0; k < pk.pos.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", pk.pos[k].x,
                  pk.pos[k].y, pk.radius[k], pk.vel[k].x, pk.vel[k].y, pk.spin[k]);
    f << buf;
  }
}

// The packing of `path` if it exists, its first line holds `version` and it has n particles.
inline std::optional<Packing> read_packing(const std::string& path, const std::string& version,
                                           std::int64_t n) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  std::string header;
  std::getline(in, header);
  if (header.find(version) == std::string::npos) return std::nullopt;
  Packing out;
  out.from_cache = true;
  out.recipe = header.size() > 2 ? header.substr(2) : header;
  std::string line;
  std::getline(in, line);  // column names
  while (std::getline(in, line)) {
    double x, y, r, vx, vy, w;
    char c[5];
    std::istringstream ls(line);
    if (ls >> x >> c[0] >> y >> c[1] >> r >> c[2] >> vx >> c[3] >> vy >> c[4] >> w) {
      out.pos.push_back({x, y});
      out.radius.push_back(r);
      out.vel.push_back({vx, vy});
      out.spin.push_back(w);
    }
  }
  if (static_cast<std::int64_t>(out.pos.size()) != n) return std::nullopt;
  return out;
}

inline std::string drum_cache_path(std::int64_t n, const std::string& cache_dir) {
  return cache_dir + "/settled_drum_" + std::to_string(n) + ".csv";
}

inline std::string deposited_cache_path(std::int64_t n, const std::string& cache_dir) {
  return cache_dir + "/deposited_drum_" + std::to_string(n) + ".csv";
}

// The drum packing of N particles if the cache holds it (never settles): DIR/settled_drum_<N>.csv
// below kDepositFrom, the deposited bed's file from there on (settled_packing).
inline std::optional<Packing> cached_packing(std::int64_t n, const std::string& cache_dir) {
  if (n >= kDepositFrom) {
    std::optional<Packing> pk =
        read_packing(deposited_cache_path(n, cache_dir), kDepositCacheVersion, n);
    if (pk) pk->deposited = true;
    return pk;
  }
  return read_packing(drum_cache_path(n, cache_dir), kCacheVersion, n);
}

// The deposited drum packing of N particles (header), loaded: read from
// DIR/deposited_drum_<N>.csv or made and written there.
inline Packing deposited_packing(std::int64_t n, const std::string& cache_dir,
                                 bool verbose = true) {
  const std::string path = deposited_cache_path(n, cache_dir);
  if (std::optional<Packing> pk = read_packing(path, kDepositCacheVersion, n)) {
    pk->deposited = true;
    return *pk;
  }
  if (verbose) {
    std::printf("   depositing and loading %lld particles (cached afterwards in %s) ...\n",
                static_cast<long long>(n), path.c_str());
    std::fflush(stdout);
  }
  const auto t0 = std::chrono::steady_clock::now();
  Packing out = deposit_packing(n);
  load_in_steel(out, 1.0e-6, kDepositLoadChunks, deposited_material(), kDepositLoadedSpeed);
  out.settle_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::ostringstream head;
  head << kDepositCacheVersion << ": N = " << n << ", drum radius " << drum_radius_for(n) << " m; "
       << out.recipe << "; loaded in steel with e = 0.1, mu_s = 0.5 for " << out.load_steps
       << " steps (" << out.contacts_per_particle << " contacts per particle, mean speed "
       << out.mean_speed << " m/s); " << out.settle_wall << " s of wall time";
  out.recipe = head.str();
  std::filesystem::create_directories(cache_dir);
  write_packing(path, out.recipe, out);
  return out;
}

inline std::string settle_note(const Packing& out) {
  std::ostringstream f;
  f << "overlaps removed in " << out.relax_rounds << " rounds (residual " << out.residual_overlap
    << " m), loaded in steel for " << out.load_steps << " steps (" << out.contacts_per_particle
    << " contacts per particle); " << out.settle_wall << " s of wall time";
  return f.str();
}

// The settled drum packing of N particles (header: deposited for N >= 300 000), read from
// DIR/settled_drum_<N>.csv or made and written there.
inline Packing settled_packing(std::int64_t n, const std::string& cache_dir, bool verbose = true) {
  if (n >= kDepositFrom) return deposited_packing(n, cache_dir, verbose);
  const std::string path = drum_cache_path(n, cache_dir);
  if (std::optional<Packing> pk = cached_packing(n, cache_dir)) return *pk;
  if (verbose) {
    std::printf("   settling %lld particles (cached afterwards in %s) ...\n",
                static_cast<long long>(n), path.c_str());
    std::fflush(stdout);
  }
  Packing out = settle_packing(n);
  std::ostringstream head;
  head << kCacheVersion << ": N = " << n << ", drum radius " << drum_radius_for(n) << " m; "
       << "settled soft (E x " << soft_factor_for(n) << ") for " << out.settle_time << " s, "
       << settle_note(out);
  out.recipe = head.str();
  std::filesystem::create_directories(cache_dir);
  write_packing(path, out.recipe, out);
  return out;
}

// The settled size-ratio packing (header), read from DIR/settled_ratio<ratio>_<N>.csv or settled
// and written there.
inline Packing ratio_packing(std::int64_t n, double ratio, const std::string& cache_dir,
                             bool verbose = true) {
  char name[64];
  std::snprintf(name, sizeof name, "/settled_ratio%g_%lld.csv", ratio, static_cast<long long>(n));
  const std::string path = cache_dir + name;
  if (std::optional<Packing> pk = read_packing(path, kRatioCacheVersion, n)) {
    pk->drum_radius = ratio_drum_radius(n, ratio);
    return *pk;
  }
  if (verbose) {
    std::printf("   settling %lld particles of size ratio %g (cached afterwards in %s) ...\n",
                static_cast<long long>(n), ratio, path.c_str());
    std::fflush(stdout);
  }
  Packing out = settle_ratio_packing(n, ratio);
  std::ostringstream head;
  head << kRatioCacheVersion << ": N = " << n << ", size ratio " << ratio
       << ", radii log-uniform in [" << kRadiusMax / ratio << ", " << kRadiusMax
       << "] m, drum radius " << out.drum_radius << " m; random sequential placement, settled "
       << "soft for " << out.settle_time << " s, " << settle_note(out);
  out.recipe = head.str();
  std::filesystem::create_directories(cache_dir);
  write_packing(path, out.recipe, out);
  return out;
}

}  // namespace bench
