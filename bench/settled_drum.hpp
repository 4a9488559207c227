// settled_drum.hpp: a settled charge of polydisperse steel spheres in a circular drum, shared by
// bench/throughput.cpp and bench/bm_kernels.cpp (header only: bench/CMakeLists.txt builds each
// bench/*.cpp as its own program).
//
// The charge: N steel spheres (thesis steel: rho 7800, E 2e11 Pa, G 8e10 Pa, e = 0.73,
// mu_s = 0.1, mu_r = 0.05), radius uniform in [6, 10] mm, in a circular drum (sides = 0) of
// radius R(N) = 2.5 m sqrt(N / 30 000) (fill fraction 0.31 at every N) turning at
// 1.5 rad/s sqrt(2.5 m / R) (Froude number 0.57 at every N). N = 30 000 is the 2.5 m drum at
// 1.5 rad/s. Contact law hertz-mindlin with epsd rolling resistance.
//
// Settling (cheap, not what is measured), in three stages, all with the drum still:
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
// Positions, velocities (a few cm/s) and spins are cached in DIR/settled_drum_<N>.csv
// (x, y, radius, vx, vy, spin), as settling 1e5 particles takes several minutes: delete the
// file to settle again. The measured runs (settled_scene) start from it with the drum turning
// at full speed; the benches run 500 untimed steps first.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/scene.hpp"
#include "core/simulation.hpp"

namespace bench {

constexpr double kRadiusMin = 0.006, kRadiusMax = 0.010;  // m
constexpr double kRefN = 30000.0, kRefDrum = 2.5, kRefSpeed = 1.5;
constexpr const char* kCacheVersion = "settled_drum v7";  // bump when the recipe changes

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
};

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

// A scene of the packing's particles (with their velocities) in `material`, dt given.
inline dem2d::Scene packing_scene(const Packing& pk, const dem2d::MaterialSpec& material,
                                  double drum_speed, double dt) {
  const double radius = drum_radius_for(static_cast<std::int64_t>(pk.pos.size()));
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

// The measured scene: steel, the drum turning at its full speed from t = 0.
inline dem2d::Scene settled_scene(const Packing& pk, double dt) {
  const double radius = drum_radius_for(static_cast<std::int64_t>(pk.pos.size()));
  return packing_scene(pk, steel(1.0), drum_speed_for(radius), dt);
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

inline Packing settle_packing(std::int64_t n) {
  const auto t0 = std::chrono::steady_clock::now();
  const double radius = drum_radius_for(n);
  Packing out;
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
  s.run.dt = half_limit_dt(s);
  s.run.dt_auto = false;
  s.run.allow_unsafe_dt = true;
  dem2d::Simulation sim(s);
  double mass = 0.0;
  for (std::size_t k = 0; k < sim.particles().n_owned(); ++k) mass += sim.particles().mass[k];
  while (true) {
    sim.run_until(sim.time() + 0.05);
    const double v = std::sqrt(2.0 * sim.diagnostics().kinetic_energy / mass);
    if ((sim.time() >= 0.4 && v < 0.02) || sim.time() >= 1.0) break;
  }
  out.settle_time = sim.time();
  take_state(sim, out);  // (the store is in id order: the core has not reordered it)
  // Stage 2: relaxation rounds, each with the candidate pairs of the positions it starts from.
  dem2d::ParticleStore& store = sim.particles();
  bool relaxed = false;
  double worst = 0.0;
  for (int round = 0; round < 2000 && !relaxed; ++round) {
    for (std::size_t k = 0; k < out.pos.size(); ++k)
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
  for (std::size_t k = 0; k < out.pos.size(); ++k)
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
  // Stage 3: steel until the contacts stop growing.
  {
    dem2d::Simulation steel_sim(packing_scene(out, steel(1.0), 0.0, 1.0e-6));
    double contacts = 0.0;
    for (int chunk = 0; chunk < 20; ++chunk) {
      for (int k = 0; k < 1000; ++k) steel_sim.step();
      const double c = static_cast<double>(steel_sim.last_totals().contacts);
      const bool flat = c < 1.01 * contacts;
      contacts = c;
      if (chunk >= 2 && flat) break;
    }
    out.load_steps = steel_sim.step_count();
    out.contacts_per_particle = contacts / static_cast<double>(n);
    take_state(steel_sim, out);
  }
  out.settle_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

// The settled packing of N particles, read from DIR/settled_drum_<N>.csv or settled and written
// there.
inline Packing settled_packing(std::int64_t n, const std::string& cache_dir, bool verbose = true) {
  const std::string path = cache_dir + "/settled_drum_" + std::to_string(n) + ".csv";
  if (std::ifstream in(path); in) {
    std::string header;
    std::getline(in, header);
    if (header.find(kCacheVersion) != std::string::npos) {
      Packing out;
      out.from_cache = true;
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
      if (static_cast<std::int64_t>(out.pos.size()) == n) return out;
    }
  }
  if (verbose) {
    std::printf("   settling %lld particles (cached afterwards in %s) ...\n",
                static_cast<long long>(n), path.c_str());
    std::fflush(stdout);
  }
  Packing out = settle_packing(n);
  std::filesystem::create_directories(cache_dir);
  std::ofstream f(path);
  f << "# " << kCacheVersion << ": N = " << n << ", drum radius " << drum_radius_for(n)
    << " m; settled soft (E x " << soft_factor_for(n) << ") for " << out.settle_time
    << " s, overlaps removed in " << out.relax_rounds << " rounds (residual "
    << out.residual_overlap << " m), loaded in steel for " << out.load_steps << " steps ("
    << out.contacts_per_particle << " contacts per particle); " << out.settle_wall
    << " s of wall time\n";
  f << "x,y,radius,vx,vy,spin\n";
  char buf[256];
  for (std::size_t k = 0; k < out.pos.size(); ++k) {
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", out.pos[k].x,
                  out.pos[k].y, out.radius[k], out.vel[k].x, out.vel[k].y, out.spin[k]);
    f << buf;
  }
  return out;
}

}  // namespace bench
