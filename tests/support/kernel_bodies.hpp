// A few bodies (and the scene's walls) run by one force kernel with velocity Verlet, the lists
// rebuilt every step: the harness of the shape tests, which compare a shape's general path with
// the disc kernel step by step and follow single impacts. `shaped`: the store carries the shape
// fields (a disc there is a = b = r, n = 2); the scene's particles with semi-axes are added as
// superellipses, the others as discs.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/base/scene.hpp"
#include "core/contact/kernel_factory.hpp"
#include "core/contact/neighbors.hpp"

namespace dem2d::testing_support {

template <class Model, class Shape>
struct KernelBodies {
  Scene scene;
  PairTable table;
  Walls walls;
  kernels::Kernel<Model, Shape> kernel;
  ParticleStore p;
  NeighborSearch search;
  PairList pl;
  WallPairList wl;
  std::vector<WallLoad> loads;
  EvaluationTotals tot;
  std::vector<double> inertia;  // each body's moment of inertia
  double dt;
  double dissipated = 0.0;  // summed over the evaluations

  explicit KernelBodies(const Scene& s, bool shaped = false)
      : scene(s), table(s), walls(s), kernel(s.contact, table), dt(s.run.dt) {
    pl.width = wl.width = kernel.history_slots().size();
    search.set_pair_trials(true);
    if (shaped) p.enable_shape();
    for (std::size_t k = 0; k < s.particles.size(); ++k) {
      const ParticleSpec& b = s.particles[k];
      if (b.shaped())
        p.add_shaped(static_cast<std::int64_t>(k), 0, b.semi_a, b.semi_b, b.exponent,
                     s.materials[0].density, b.position, b.velocity, b.spin, b.angle);
      else
        p.add(static_cast<std::int64_t>(k), 0, b.radius, s.materials[0].density, b.position,
              b.velocity, b.spin);
      inertia.push_back(1.0 / p.inv_inertia[k]);
    }
  }
  // Mass and moment of inertia of body k set by hand.
  void set_inertia(std::size_t k, double m, double moment) {
    p.mass[k] = m;
    p.inv_mass[k] = 1.0 / m;
    p.inv_inertia[k] = 1.0 / moment;
    inertia[k] = moment;
  }
  void forces() {
    search.build(p, walls, 0.2 * p.radius[0], pl, wl);
    kernel.lists_changed();
    for (std::size_t k = 0; k < p.size(); ++k) {
      p.force[k] = p.mass[k] * scene.run.gravity;
      p.torque[k] = 0.0;
      p.elastic_force[k] = {};
    }
    kernel.evaluate(p, walls, pl, wl, dt, tot, loads);
    dissipated += tot.dissipated;
    if (!kernel.histories_in_place()) pl.history.swap(pl.trial);
    wl.history.swap(wl.trial);
    kernel.committed();
  }
  void kick() {
    for (std::size_t k = 0; k < p.size(); ++k) {
      p.vel[k] += (0.5 * dt * p.inv_mass[k]) * p.force[k];
      p.omega[k] += 0.5 * dt * p.inv_inertia[k] * p.torque[k];
    }
  }
  void step() {
    kick();
    for (std::size_t k = 0; k < p.size(); ++k) {
      p.pos[k] += dt * p.vel[k];
      p.theta[k] += dt * p.omega[k];
    }
    forces();
    kick();
  }
  double kinetic() const {
    double e = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k)
      e += 0.5 * p.mass[k] * norm2(p.vel[k]) + 0.5 * inertia[k] * p.omega[k] * p.omega[k];
    return e;
  }
  Vec2 momentum() const {
    Vec2 out{};
    for (std::size_t k = 0; k < p.size(); ++k) out += p.mass[k] * p.vel[k];
    return out;
  }
  // About the origin: the sum of m x cross v + I w.
  double angular_momentum() const {
    double out = 0.0;
    for (std::size_t k = 0; k < p.size(); ++k)
      out += p.mass[k] * cross(p.pos[k], p.vel[k]) + inertia[k] * p.omega[k];
    return out;
  }
};

}  // namespace dem2d::testing_support
