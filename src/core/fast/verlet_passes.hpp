// Velocity Verlet's passes over the owned particles, the fast paths beside their scalar
// reference: the opening half kick and drift, the closing half kick fused with the accelerations,
// and the two fused in one pass (the closing kick of one step with the next step's kick-drift).
// With AVX-512 each pass takes four particles per iteration with the same operations in the same
// order as the one-particle code (no FMA), so the same bits; test_core VelocityVerletDrift and
// VelocityVerletRunAhead compare them. The integrators (core/step/integrators.hpp) call them.
#pragma once

#include <cstddef>

#include "core/base/vec2.hpp"
#include "core/fast/kinematics_mirror.hpp"
#include "core/shape/particles.hpp"

namespace dem2d {

// a = F/m + g and alpha = M/I of one particle, gravity added last, the same way for every
// particle.
[[gnu::always_inline]] inline void accelerate(Vec2& a, double& alpha, Vec2 f, double torque,
                                              double inv_m, double inv_i, Vec2 gravity) {
  a = inv_m * f + gravity;
  alpha = inv_i * torque;
}

// Velocity Verlet's opening half kick and drift of one particle. The same operations serve the
// owned particles and the state a halo source's ghosts are handed ahead, so the bits agree.
struct Drifted {
  Vec2 x, v;
  double w;
};
[[gnu::always_inline]] inline Drifted kick_drift(Vec2 x, Vec2 v, Vec2 a, double w, double alpha,
                                                 double h, double dt) {
  const Vec2 v_half = v + h * a;
  return {x + dt * v_half, v_half, w + h * alpha};
}

// Velocity Verlet's opening half kick and drift of the owned particles of `p`, force and torque
// cleared, and with `mirror` (not null) their pair-gather lines (core/fast/kinematics_mirror.hpp).
// With AVX-512 and `four_at_a_time`, four particles per iteration: the same operations in the
// same order, so the same bits (test_core VelocityVerletDrift compares the two).
void kick_drift_owned(ParticleStore& p, double dt, PairKinematics* mirror,
                      bool four_at_a_time = true);

// Velocity Verlet's closing half kick of the owned particles, fused with the accelerations
// (a = F/m + g, alpha = M/I, v += a dt/2, w += alpha dt/2, elastic forces cleared), and what the
// step's round needs:
//   checksum   sum of (a_x + a_y) + alpha + (x + y): not finite when something blew up,
//   disp2      max |x - x_build|^2, speed2 max |v + a dt/2|^2, motion2 max |v + a dt/2|^2 / r^2,
//   late_loss  J, the energy ledger's completion (integrators.cpp).
// The two sums are taken in one fixed order whatever the loop: eight running sums, particle k
// of the first 8 floor(n / 8) into sum k mod 8 and the rest into sum 0, then the eight added in
// turn (the order of the compiler's eight-wide loop this replaced: the ledger kept its bits).
struct ClosingKick {
  double checksum = 0.0;
  double disp2 = 0.0, speed2 = 0.0, motion2 = 0.0;
  double late_loss = 0.0;
};
// With AVX-512 and `four_at_a_time`, four particles per iteration (the same bits).
ClosingKick closing_kick(ParticleStore& p, const Vec2* x_build, double dt, Vec2 gravity,
                         bool four_at_a_time = true);
// closing_kick and then the next step's kick_drift_owned in one pass over the store: the same
// fields, the same mirror lines and the same ClosingKick, bit for bit (test_core
// VelocityVerletRunAhead). With AVX-512 and `four_at_a_time`, four particles per iteration.
ClosingKick closing_kick_drift(ParticleStore& p, const Vec2* x_build, double dt, Vec2 gravity,
                               PairKinematics* mirror, bool four_at_a_time = true);

}  // namespace dem2d
