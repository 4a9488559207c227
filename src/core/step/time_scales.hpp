// Time scales of a scene: what dt = "auto" picks and what a dt may not exceed (docs/models.md,
// "The time step, stability and guards"; shown by --check).
#pragma once

#include <string>

#include "core/base/scene.hpp"
#include "core/shape/particles.hpp"

namespace dem2d {

// Derived time scales of a scene (shown by --check).
struct TimeScales {
  double rayleigh = 0.0;         // s, smallest Rayleigh time pi r sqrt(rho/G)/(0.1631 nu + 0.8766)
  double hertz = 0.0;            // s, smallest Hertz contact time: particle pairs and walls
  double impact_speed = 0.0;     // m/s, largest expected closing speed (pairs or walls)
  double restitution_min = 1.0;  // smallest restitution of the material pairs present
  double steps_per_contact = 0.0;  // Hertz contact resolved with this many steps (see below)
  double safe_dt = 0.0;            // s, what dt = "auto" picks
  double limit_dt = 0.0;           // s, above this a dt is refused: 0.5 * min(rayleigh, hertz)
  // What sets them, for --check: the pair of the shortest contact time and the pair of the
  // smallest restitution, e.g. "ore against ore" or "ore against the walls of steel".
  std::string hertz_pair, restitution_pair;
};

// Steps per Hertz contact that keep the restitution obtained within 1 % of the one asked
// (measured with both integrators, head-on steel at 40 m/s, worst of 8 contact phases: the
// error is first order, about C(e)/steps with C = 32 (-ln e / ln 2)^1.77 %, from where contact
// starts and ends inside a step). N = max(20, 50 (-ln e / ln 2)^1.77) aims at 0.65 %: 20 for
// e >= 0.7, 50 at e = 0.5, 420 at e = 0.1.
double steps_per_contact_for(double restitution);
TimeScales time_scales(const Scene& scene, const ParticleStore& particles);

}  // namespace dem2d
