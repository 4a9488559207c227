// Contact laws (physics.md sections 2-3). Each law is a small value type with one static
// `evaluate`; the pair loop (core/forces.hpp) is written once and instantiated per
// (law, rolling model) at setup, so a scene pays only for the models it uses.
//
// Kinematics of one contact (sphere i, body j), lower id first:
//   n from i to j, t = perp(n) = (-n_y, n_x), overlap delta = r_i + r_j - |x_j - x_i| > 0,
//   v_rel = (v_i - v_j) + (w_i r_i + w_j r_j) t,  v_n = v_rel . n (> 0 closing),
//   v_t = v_rel . t,  w_rel = w_i - w_j.
//   Force on i: -F_n n + F_t t, on j the opposite. Torque on i and on j: arm * F_t, with
//   arm = r_i, r_j (hertz-mindlin, linear) or R* (thesis, T15). Rolling torque M on i, -M on j.
// Every law also reports the energy it dissipated in the step (J) and the elastic energy it
// stores, so that kinetic + potential + elastic + dissipated - drive work stays constant.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/materials.hpp"

namespace dem2d {

struct ContactKinematics {
  double delta = 0.0;      // overlap, m (> 0)
  double r_eff = 0.0;      // R*, m
  double m_eff = 0.0;      // m*, kg
  double i_eff = 0.0;      // rolling inertia, kg m^2 (epsd only)
  double v_n = 0.0;        // m/s, > 0 while closing
  double v_t = 0.0;        // m/s, sliding speed of i's contact point relative to j, along t
  double omega_rel = 0.0;  // rad/s, w_i - w_j
};

// State a contact carries from step to step; created at first touch, deleted when it ends.
struct ContactHistory {
  double xi = 0.0;      // tangential spring elongation, m (2D: one scalar)
  double m_roll = 0.0;  // epsd rolling spring torque, N m
};

struct ContactForce {
  double f_n = 0.0;         // N, >= 0 (never attractive)
  double f_t = 0.0;         // N, on i along t
  double k_n = 0.0;         // N/m, normal tangent stiffness (feeds the epsd rolling spring)
  double k_rate = 0.0;      // 1/s, d(ln k_n)/dt: Hertz stiffness ~ sqrt(delta) -> v_n / (2 delta)
  double dissipated = 0.0;  // J in this step
  double elastic = 0.0;     // J stored (normal + tangential springs)
};

inline double sign(double x) { return (x > 0.0) - (x < 0.0); }

// Tangential spring-dashpot with a Coulomb cap (hertz-mindlin and linear):
//   xi += v_t dt, F_t = -k_t xi - c_t v_t, |F_t| <= mu_s F_n; when capped, xi shrinks so the
//   spring alone equals the cap.
// Dissipation: the dashpot's c_t v_t^2 dt while the spring holds; while sliding, the work of
// the force on the slip minus the change of the spring's energy. (Charging -F_t v_t dt - dU in
// both cases would count a spurious k_t dxi^2 / 2 each step: an O(dt) drift in the balance.)
// A spring whose stiffness follows the overlap (Hertz: k ~ sqrt(delta)) is not derived from a
// potential: holding xi while delta changes changes 1/2 k xi^2 with no force doing work. That
// change, 1/2 k xi^2 d(ln k)/dt dt, is booked as dissipated (it may be negative) so that the
// energy balance closes; `k_rate` is d(ln k)/dt (0 for a constant stiffness).
[[gnu::always_inline]] inline void tangential_spring(double k_t, double k_rate, double c_t, double mu_s, double f_n,
                              double v_t, double dt, double xi_old, ContactHistory& h,
                              ContactForce& out) {
  out.dissipated -= 0.5 * k_t * xi_old * xi_old * k_rate * dt;
  double xi = xi_old + v_t * dt;
  double f_t = -k_t * xi - c_t * v_t;
  const double cap = mu_s * f_n;
  if (std::abs(f_t) > cap) {
    f_t = std::copysign(cap, f_t);
    xi = k_t > 0.0 ? -f_t / k_t : 0.0;
    out.dissipated += -f_t * v_t * dt - 0.5 * k_t * (xi * xi - xi_old * xi_old);
  } else {
    out.dissipated += c_t * v_t * v_t * dt;
  }
  h.xi = xi;
  out.f_t = f_t;
  out.elastic += 0.5 * k_t * xi * xi;
}

// Hertz-Mindlin "no-slip" (seed 004, EDEM):
//   S_n = 2 E* sqrt(R* delta), F_n = 4/3 E* sqrt(R*) delta^1.5 - 2 sqrt(5/6) beta sqrt(S_n m*) v_n,
//   S_t = 8 G* sqrt(R* delta), F_t = -S_t xi - 2 sqrt(5/6) beta sqrt(S_t m*) v_t, |F_t| <= mu_s F_n,
//   beta mapped from the restitution asked for the clamped law (materials.hpp).
struct HertzMindlin {
  static constexpr bool kTorqueArmIsReff = false;
  [[gnu::always_inline]] static ContactForce evaluate(const PairCoeffs& c, const ContactKinematics& k,
                               const ContactHistory& old, ContactHistory& h, double dt) {
    ContactForce out;
    const double s = std::sqrt(k.r_eff * k.delta);
    const double s_n = 2.0 * c.e_star * s;
    const double f_el = (2.0 / 3.0) * s_n * k.delta;
    const double root = std::sqrt(s_n * k.m_eff);
    const double f_n = std::max(0.0, f_el + c.damp * root * k.v_n);
    out.f_n = f_n;
    out.k_n = s_n;
    out.dissipated = (f_n - f_el) * k.v_n * dt;
    out.elastic = 0.4 * f_el * k.delta;  // 8/15 E* sqrt(R*) delta^2.5
    out.k_rate = 0.5 * k.v_n / k.delta;  // d ln sqrt(delta) / dt, with d(delta)/dt = v_n
    const double s_t = 8.0 * c.g_star * s;
    tangential_spring(s_t, out.k_rate, c.damp * c.tangential_ratio * root, c.mu_s, f_n, k.v_t, dt,
                      old.xi, h, out);
    return out;
  }
};

// The thesis's law as written (T9-T23): Hertz stiffness k_n = 4/3 E* sqrt(R* delta) (T11),
// viscous normal damping c_n = 2 zeta_n sqrt(m* S_n) (T22), pure Coulomb sliding
// F_s = mu_s F_n sign(v_t) (T13) plus tangential damping c_t = 4 zeta_t sqrt(m* 2 G* sqrt(R* delta))
// (T23), torques with the arm R* (T15). Normal force clamped at zero like the others.
struct ThesisModel {
  static constexpr bool kTorqueArmIsReff = true;
  [[gnu::always_inline]] static ContactForce evaluate(const PairCoeffs& c, const ContactKinematics& k,
                               const ContactHistory&, ContactHistory& h, double dt) {
    ContactForce out;
    const double s = std::sqrt(k.r_eff * k.delta);
    const double s_n = 2.0 * c.e_star * s;
    const double f_el = (4.0 / 3.0) * c.e_star * s * k.delta;
    const double c_n = 2.0 * c.zeta_n * std::sqrt(k.m_eff * s_n);
    const double f_n = std::max(0.0, f_el + c_n * k.v_n);
    const double c_t = 4.0 * c.zeta_t * std::sqrt(k.m_eff * 2.0 * c.g_star * s);
    const double f_t = -c.mu_s * f_n * sign(k.v_t) - c_t * k.v_t;
    h.xi = 0.0;
    out.f_n = f_n;
    out.f_t = f_t;
    out.k_n = s_n;
    out.k_rate = 0.5 * k.v_n / k.delta;
    out.dissipated = (f_n - f_el) * k.v_n * dt - f_t * k.v_t * dt;
    out.elastic = 0.4 * f_el * k.delta;
    return out;
  }
};

// Linear spring-dashpot (Cundall & Strack 1979): k_n constant per pair (or 4/3 E* 0.1 R*),
// c_n = 2 gamma sqrt(k_n m*) with gamma mapped from the restitution for the clamped law,
// k_t = 2/7 k_n (equal normal and tangential periods for a sphere), c_t = 2 gamma sqrt(k_t m*).
struct LinearModel {
  static constexpr bool kTorqueArmIsReff = false;
  [[gnu::always_inline]] static ContactForce evaluate(const PairCoeffs& c, const ContactKinematics& k,
                               const ContactHistory& old, ContactHistory& h, double dt) {
    ContactForce out;
    const double k_n = c.kn_const + c.kn_per_radius * k.r_eff;
    const double f_el = k_n * k.delta;
    const double f_n = std::max(0.0, f_el + 2.0 * c.gamma_linear * std::sqrt(k_n * k.m_eff) * k.v_n);
    out.f_n = f_n;
    out.k_n = k_n;
    out.dissipated = (f_n - f_el) * k.v_n * dt;
    out.elastic = 0.5 * f_el * k.delta;
    const double k_t = (2.0 / 7.0) * k_n;
    tangential_spring(k_t, 0.0, 2.0 * c.gamma_linear * std::sqrt(k_t * k.m_eff), c.mu_s, f_n,
                      k.v_t, dt, old.xi, h, out);
    return out;
  }
};

struct RollingTorque {
  double torque = 0.0;      // N m on i
  double dissipated = 0.0;  // J in this step
  double elastic = 0.0;     // J stored in the rolling spring
};

// No rolling resistance: nothing is computed.
struct RollingNone {
  static constexpr bool kActive = false;
  static constexpr bool kNeedsInertia = false;
  [[gnu::always_inline]] static RollingTorque evaluate(const PairCoeffs&, const ContactKinematics&, const ContactForce&,
                                const ContactHistory&, ContactHistory&, double, double) {
    return {};
  }
};

// Constant directional torque (T16; Ai et al. 2011 model A): M = -mu_r F_n R* sign(w_rel).
struct RollingConstant {
  static constexpr bool kActive = true;
  static constexpr bool kNeedsInertia = false;
  [[gnu::always_inline]] static RollingTorque evaluate(const PairCoeffs& c, const ContactKinematics& k,
                                const ContactForce& cf, const ContactHistory&, ContactHistory&,
                                double dt, double) {
    const double m = -c.mu_r * cf.f_n * k.r_eff * sign(k.omega_rel);
    return {m, -m * k.omega_rel * dt, 0.0};
  }
};

// Elastic-plastic spring-dashpot (Ai et al. 2011 model C):
//   k_r = 2.25 k_n mu_r^2 R*^2, M_k += -k_r w_rel dt, |M_k| <= M_max = mu_r R* F_n,
//   M_d = -eta_r 2 sqrt(I_r k_r) w_rel while |M_k| < M_max (off at full mobilisation), and
//   |M_k + M_d| <= M_max: the dashpot cannot push the torque past the cap either.
// eta_r is `rolling_damping` (ContactSpec), passed in as `eta`.
struct RollingEpsd {
  static constexpr bool kActive = true;
  static constexpr bool kNeedsInertia = true;
  [[gnu::always_inline]] static RollingTorque evaluate(const PairCoeffs& c, const ContactKinematics& k,
                                const ContactForce& cf, const ContactHistory& old,
                                ContactHistory& h, double dt, double eta) {
    const double k_r = 2.25 * cf.k_n * c.mu_r * c.mu_r * k.r_eff * k.r_eff;
    if (k_r <= 0.0) {
      h.m_roll = 0.0;
      return {};
    }
    const double m_max = c.mu_r * k.r_eff * cf.f_n;
    double m_k = old.m_roll - k_r * k.omega_rel * dt;
    const double half_compliance = 0.5 / k_r;
    // Stiffness change at constant torque (see tangential_spring): U = M^2 / (2 k_r) changes by
    // -U d(ln k_r)/dt dt with no work done; booked as dissipated.
    const double stiffness_change = half_compliance * old.m_roll * old.m_roll * cf.k_rate * dt;
    if (std::abs(m_k) >= m_max) {  // full mobilisation: plastic rolling, no dashpot
      m_k = std::copysign(m_max, m_k);
      h.m_roll = m_k;
      const double stored_change = half_compliance * (m_k * m_k - old.m_roll * old.m_roll);
      return {m_k, -m_k * k.omega_rel * dt - stored_change + stiffness_change,
              half_compliance * m_k * m_k};
    }
    const double c_r = eta * 2.0 * std::sqrt(k.i_eff * k_r);
    h.m_roll = m_k;
    const double m = m_k - c_r * k.omega_rel;
    if (std::abs(m) > m_max) {  // spring + dashpot never exceed the cap (physics.md section 3)
      const double capped = std::copysign(m_max, m);
      const double stored_change = half_compliance * (m_k * m_k - old.m_roll * old.m_roll);
      return {capped, -capped * k.omega_rel * dt - stored_change + stiffness_change,
              half_compliance * m_k * m_k};
    }
    return {m, c_r * k.omega_rel * k.omega_rel * dt + stiffness_change, half_compliance * m_k * m_k};
  }
};

}  // namespace dem2d
