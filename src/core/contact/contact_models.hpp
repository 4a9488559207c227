// Contact sub-models (docs/models.md, "Contact laws"), in three slots:
//   law      normal and tangential force: HertzMindlin, ThesisModel, LinearModel;
//   rolling  rolling resistance: RollingNone, RollingConstant, RollingEpsd;
//   tracker  what a contact records for other models: TrackNone, TrackPeakEnergy;
//   stepper  the speeds that advance the springs over a step, which depend on the integrator:
//            StepAsSeen (Verlet), StepTrapezoid (iterative).
// Each sub-model is a small value type that owns
//   - its coefficients: `Coeffs<V>` (V = double for one material pair, Pack for one pair per
//     lane), made from the pair's mixed material properties by `coeffs(MaterialPair)`, with
//     `tie()` listing the members once (the kernel gathers packs through it);
//   - its history: `kHistory`, the slots it carries from step to step (name, unit, meaning);
//     `History<T>` holds them. The contact's history is law + rolling + tracker slots, and the
//     neighbour lists, migration and (later) checkpoints size themselves from it;
//   - one static `evaluate`.
// ContactModel<Law, Rolling, Tracker, Stepper> composes them; the pair and wall paths of the force
// kernel (contact_engine.cpp) call its one `evaluate`. The combination is chosen once at setup
// (make_contact_kernel), so a scene pays only for the models it uses.
//
// Kinematics of one contact (sphere i, body j), lower id first:
//   n from i to j, t = perp(n) = (-n_y, n_x), overlap delta = r_i + r_j - |x_j - x_i| > 0,
//   v_rel = (v_i - v_j) + (w_i r_i + w_j r_j) t,  v_n = v_rel . n (> 0 closing),
//   v_t = v_rel . t,  w_rel = w_i - w_j.
//   Force on i: -F_n n + F_t t, on j the opposite. Torque on i and on j: arm * F_t, with
//   arm = r_i, r_j (hertz-mindlin, linear) or R* (thesis, T15). Rolling torque M on i, -M on j.
// Every law also reports the energy it dissipated in the step (J) and the elastic energy it
// stores, so that kinetic + potential + elastic + dissipated - drive work stays constant.
//
// Each law is written once, generic over the value type T: double (one contact) or Pack (a
// SIMD pack of contacts, core/fast/simd.hpp), and over the coefficient type C (the law's
// Coeffs<double>, or Coeffs<Pack> with one material pair per lane). Branches are selects, so both
// instantiations perform the same IEEE operations and give the same bits.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>

#include "core/contact/contact_history.hpp"
#include "core/contact/materials.hpp"
#include "core/fast/simd.hpp"

namespace dem2d {

template <class T>
struct KinematicsT {
  T delta = T(0.0);      // overlap, m (> 0)
  T r_eff = T(0.0);      // R*, m
  T m_eff = T(0.0);      // m*, kg
  T i_eff = T(0.0);      // rolling inertia, kg m^2 (epsd only)
  T v_n = T(0.0);        // m/s, > 0 while closing
  T v_t = T(0.0);        // m/s, sliding speed of i's contact point relative to j, along t
  T omega_rel = T(0.0);  // rad/s, w_i - w_j
  // The step's mean normal, sliding and rolling speeds, which advance the springs and give the
  // overlap at the step's start (set by the stepper: Verlet, the half-step values above;
  // iterative, the mean of the step's start and end).
  T v_n_step = T(0.0);
  T v_t_step = T(0.0);
  T omega_rel_step = T(0.0);
};
using ContactKinematics = KinematicsT<double>;

// A sub-model's history values for one contact (or one per lane): created zero at first
// touch, deleted when the contact ends.
template <class T, std::size_t N>
using HistoryArray = std::array<T, N>;

template <class T>
struct ContactForceT {
  T f_n = T(0.0);  // N, >= 0 (never attractive)
  T f_t = T(0.0);  // N, on i along t
  T k_n = T(0.0);  // N/m, normal tangent stiffness (feeds the epsd rolling spring)
  // k_n(delta_old) / k_n(delta) with delta_old = delta - v_n dt, the overlap at the start of the
  // step: how much the stiffness of the springs that follow k_n (tangential, rolling) changed
  // over the step (Hertz: sqrt(delta_old / delta), 0 at first touch; constant stiffness: 1).
  T k_prev_ratio = T(1.0);
  T dissipated = T(0.0);  // J in this step
  T elastic = T(0.0);     // J stored (normal + tangential springs)
  T strain =
      T(0.0);  // J, the normal elastic energy the breakage law reads (docs/models.md, grinding)
  // The elastic part of f_n (N): the one force whose work is not booked in `dissipated` (its
  // work is the change of the elastic energy). The work of everything else (normal dashpot, the
  // whole tangential force, the rolling torque) is booked with the velocities the law sees; the
  // integrator completes it to the velocities its kicks actually use (VelocityVerlet::
  // closing_kick, IterativeIntegrator::late_loss), which makes the booking exact.
  T f_el = T(0.0);
};
using ContactForce = ContactForceT<double>;

template <class T>
struct RollingTorqueT {
  T torque = T(0.0);      // N m on i
  T dissipated = T(0.0);  // J in this step
  T elastic = T(0.0);     // J stored in the rolling spring
};
using RollingTorque = RollingTorqueT<double>;

// Coefficients of one lane each: lane l takes at(l) (a Coeffs<double>), member by member
// through `tie()`.
template <template <class> class Coeffs, class At>
[[gnu::always_inline]] inline Coeffs<Pack> gather_coeffs(At at) {
  Coeffs<Pack> out;
  auto dst = Coeffs<Pack>::tie(out);
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    ((std::get<I>(dst) = Pack([&](auto l) { return std::get<I>(Coeffs<double>::tie(at(l))); })),
     ...);
  }
  (std::make_index_sequence<std::tuple_size_v<decltype(dst)>>{});
  return out;
}
// The same coefficients in every lane.
template <template <class> class Coeffs>
inline Coeffs<Pack> broadcast_coeffs(const Coeffs<double>& c) {
  Coeffs<Pack> out;
  auto dst = Coeffs<Pack>::tie(out);
  const auto src = Coeffs<double>::tie(c);
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    ((std::get<I>(dst) = Pack(std::get<I>(src))), ...);
  }
  (std::make_index_sequence<std::tuple_size_v<decltype(dst)>>{});
  return out;
}

inline double sign(double x) { return vsign(x); }

// k(delta_old) / k(delta) for a stiffness ~ sqrt(delta) (Hertz), delta_old = delta - v_n dt the
// overlap at the start of the step (0 if the contact began within it), v_n the step's mean.
template <class T>
[[gnu::always_inline]] inline T hertz_stiffness_ratio(const KinematicsT<T>& k, double dt) {
  return vsqrt(vmax(T(0.0), k.delta - k.v_n_step * dt) / k.delta);
}

// Tangential spring-dashpot with a Coulomb cap (hertz-mindlin and linear):
//   xi += v_t dt, F_t = -k_t xi - c_t v_t, |F_t| <= mu_s F_n; when capped, xi shrinks so the
//   spring alone equals the cap.
// Dissipation: the work of F_t on the sliding speed minus the change of the spring's energy,
// -F_t v_t dt - (1/2 k_t xi_new^2 - 1/2 k_t xi_old^2), whether the spring holds or slips, and
// the integrator completes the work to the velocities of its kicks (ContactForceT::f_el), which
// makes the channel's booking exact for each step. (Booking only the
// dashpot's c_t v_t^2 dt while the spring holds, as before, left the spring's own integration
// error, of order dt F_t v_t, unbooked at every switch between holding and slipping: the
// oblique impact's ledger was off by 6e-4 of the loss at 150 steps per contact, first order.)
// A spring whose stiffness follows the overlap (Hertz: k ~ sqrt(delta)) is not derived from a
// potential: holding xi while delta changes changes 1/2 k xi^2 with no force doing work. That
// change, 1/2 xi^2 (k_old - k_new), is booked as dissipated (it may be negative) so that the
// energy balance closes; `k_prev_ratio` is k_old / k_new (1 for a constant stiffness). It is
// the finite change over the step, not the derivative d(ln k)/dt dt = v_n dt / (2 delta): at
// the end of a contact the overlap is of the order of v_n dt, the derivative is no longer
// small, and booking it overstated the dissipation by up to 40 % of an impact's true loss
// whatever the dt (oblique steel impact, e = 0.05, mu = 0.3).
// `v_step` advances the spring (the step's mean sliding speed; Verlet: v_t itself).
template <class T, class M>
[[gnu::always_inline]] inline void tangential_spring(T k_t, T k_prev_ratio, T c_t, M mu_s, T f_n,
                                                     T v_t, T v_step, double dt, T xi_old,
                                                     T& xi_new, ContactForceT<T>& out) {
  const T xi = xi_old + v_step * dt;
  const T f_t = -k_t * xi - c_t * v_t;
  const T cap = mu_s * f_n;
  const auto capped = vabs(f_t) > cap;
  const T f_t_capped = vcopysign(cap, f_t);
  const T xi_capped = select(k_t > 0.0, -f_t_capped / k_t, T(0.0));
  xi_new = select(capped, xi_capped, xi);
  out.f_t = select(capped, f_t_capped, f_t);
  out.dissipated = out.dissipated + 0.5 * k_t * xi_old * xi_old * (k_prev_ratio - 1.0) -
                   out.f_t * v_t * dt - 0.5 * k_t * (xi_new * xi_new - xi_old * xi_old);
  out.elastic = out.elastic + 0.5 * k_t * xi_new * xi_new;
}

// A sub-model that carries nothing from step to step.
struct NoHistory {
  static constexpr std::array<HistorySlot, 0> kHistory{};
  template <class T>
  using History = HistoryArray<T, 0>;
};

// The tangential spring's one history slot (hertz-mindlin, linear).
struct TangentialSpringHistory {
  static constexpr std::array<HistorySlot, 1> kHistory{
      {{"xi", "m", "tangential spring elongation"}}};
  template <class T>
  using History = HistoryArray<T, 1>;
};

// ---------------------------------------------------------------------------------------------
// Laws

// Hertz-Mindlin "no-slip" (the calibration study's model, as in EDEM):
//   S_n = 2 E* sqrt(R* delta), F_n = 4/3 E* sqrt(R*) delta^1.5 - 2 sqrt(5/6) beta sqrt(S_n m*) v_n,
//   S_t = 8 G* sqrt(R* delta), F_t = -S_t xi - 2 sqrt(5/6) beta sqrt(S_t m*) v_t, |F_t| <= mu_s
//   F_n, beta mapped from the restitution asked for the clamped law (materials.hpp).
// Strain energy (breakage): the Hertz energy 8/15 E* sqrt(R*) delta^2.5.
struct HertzMindlin : TangentialSpringHistory {
  static constexpr ContactModelKind kKind = ContactModelKind::kHertzMindlin;
  static constexpr bool kTorqueArmIsReff = false;
  static constexpr bool kStiffnessVanishes = true;  // at zero overlap (k ~ sqrt(delta))
  template <class V>
  struct Coeffs {
    V e_star{}, g_star{}, mu_s{};
    V damp{};              // -2 sqrt(5/6) beta >= 0
    V tangential_ratio{};  // sqrt(S_t / S_n) = sqrt(4 G* / E*)
    template <class S>
    static auto tie(S& c) {
      return std::tie(c.e_star, c.g_star, c.mu_s, c.damp, c.tangential_ratio);
    }
  };
  static Coeffs<double> coeffs(const MaterialPair& m) {
    return {m.e_star, m.g_star, m.mu_s,
            -2.0 * std::sqrt(5.0 / 6.0) * hertz_beta_for_restitution(m.restitution),
            std::sqrt(4.0 * m.g_star / m.e_star)};
  }
  template <class T, class C>
  [[gnu::always_inline]] static ContactForceT<T> evaluate(const C& c, const KinematicsT<T>& k,
                                                          const History<T>& old, History<T>& h,
                                                          double dt) {
    ContactForceT<T> out;
    const T s = vsqrt(k.r_eff * k.delta);
    const T s_n = 2.0 * c.e_star * s;
    const T f_el = (2.0 / 3.0) * s_n * k.delta;
    const T root = vsqrt(s_n * k.m_eff);
    const T f_n = vmax(T(0.0), f_el + c.damp * root * k.v_n);
    out.f_n = f_n;
    out.f_el = f_el;
    out.k_n = s_n;
    out.dissipated = (f_n - f_el) * k.v_n * dt;
    out.elastic = 0.4 * f_el * k.delta;  // 8/15 E* sqrt(R*) delta^2.5
    out.strain = out.elastic;
    out.k_prev_ratio = hertz_stiffness_ratio(k, dt);
    const T s_t = 8.0 * c.g_star * s;
    tangential_spring(s_t, out.k_prev_ratio, T(c.damp * c.tangential_ratio * root), c.mu_s, f_n,
                      k.v_t, k.v_t_step, dt, old[0], h[0], out);
    return out;
  }
  // The normal tangent stiffness and the energy the springs hold at overlap delta (what a
  // contact that ends releases: contact_engine.cpp, release).
  static double normal_stiffness(const Coeffs<double>& c, double r_eff, double delta) {
    return 2.0 * c.e_star * std::sqrt(r_eff * std::max(delta, 0.0));
  }
  static double spring_energy(const Coeffs<double>& c, double r_eff, double delta,
                              const double* h) {
    return 0.5 * 8.0 * c.g_star * std::sqrt(r_eff * std::max(delta, 0.0)) * h[0] * h[0];
  }
};

// The thesis's law as written (T9-T23): Hertz stiffness k_n = 4/3 E* sqrt(R* delta) (T11),
// viscous normal damping c_n = 2 zeta_n sqrt(m* S_n) (T22), pure Coulomb sliding
// F_s = mu_s F_n sign(v_t) (T13) plus tangential damping c_t = 4 zeta_t sqrt(m* 2 G* sqrt(R*
// delta)) (T23), torques with the arm R* (T15). Normal force clamped at zero like the others. No
// history. Strain energy (breakage): k_n delta^2 / 2 (T35).
struct ThesisModel : NoHistory {
  static constexpr ContactModelKind kKind = ContactModelKind::kThesis;
  static constexpr bool kTorqueArmIsReff = true;
  static constexpr bool kStiffnessVanishes = true;
  template <class V>
  struct Coeffs {
    V e_star{}, g_star{}, mu_s{}, zeta_n{}, zeta_t{};
    template <class S>
    static auto tie(S& c) {
      return std::tie(c.e_star, c.g_star, c.mu_s, c.zeta_n, c.zeta_t);
    }
  };
  static Coeffs<double> coeffs(const MaterialPair& m) {
    return {m.e_star, m.g_star, m.mu_s, m.zeta_n, m.zeta_t};
  }
  template <class T, class C>
  [[gnu::always_inline]] static ContactForceT<T> evaluate(const C& c, const KinematicsT<T>& k,
                                                          const History<T>&, History<T>&,
                                                          double dt) {
    ContactForceT<T> out;
    const T s = vsqrt(k.r_eff * k.delta);
    const T s_n = 2.0 * c.e_star * s;
    const T f_el = (4.0 / 3.0) * c.e_star * s * k.delta;
    const T c_n = 2.0 * c.zeta_n * vsqrt(k.m_eff * s_n);
    const T f_n = vmax(T(0.0), f_el + c_n * k.v_n);
    const T c_t = 4.0 * c.zeta_t * vsqrt(k.m_eff * 2.0 * c.g_star * s);
    const T f_t = -c.mu_s * f_n * vsign(k.v_t) - c_t * k.v_t;
    out.f_n = f_n;
    out.f_t = f_t;
    out.f_el = f_el;
    out.k_n = s_n;
    out.k_prev_ratio = hertz_stiffness_ratio(k, dt);
    out.dissipated = (f_n - f_el) * k.v_n * dt - f_t * k.v_t * dt;
    out.elastic = 0.4 * f_el * k.delta;
    out.strain = 0.5 * f_el * k.delta;
    return out;
  }
  static double normal_stiffness(const Coeffs<double>& c, double r_eff, double delta) {
    return 2.0 * c.e_star * std::sqrt(r_eff * std::max(delta, 0.0));
  }
  static double spring_energy(const Coeffs<double>&, double, double, const double*) { return 0.0; }
};

// Linear spring-dashpot (Cundall & Strack 1979): k_n constant per pair (or 4/3 E* 0.1 R*),
// c_n = 2 gamma sqrt(k_n m*) with gamma mapped from the restitution for the clamped law,
// k_t = 2/7 k_n (equal normal and tangential periods for a sphere), c_t = 2 gamma sqrt(k_t m*).
// Strain energy (breakage): k_n delta^2 / 2.
struct LinearModel : TangentialSpringHistory {
  static constexpr ContactModelKind kKind = ContactModelKind::kLinear;
  static constexpr bool kTorqueArmIsReff = false;
  static constexpr bool kStiffnessVanishes = false;
  template <class V>
  struct Coeffs {
    V mu_s{};
    V kn_const{}, kn_per_radius{};  // k_n = kn_const + kn_per_radius R*
    V gamma{};                      // damping ratio
    template <class S>
    static auto tie(S& c) {
      return std::tie(c.mu_s, c.kn_const, c.kn_per_radius, c.gamma);
    }
  };
  static Coeffs<double> coeffs(const MaterialPair& m) {
    // k_n: the mean of the materials' `normal_stiffness` when both give one; otherwise the Hertz
    // secant stiffness at an overlap of 1 % of R*, 4/3 E* sqrt(R* 0.01 R*).
    const bool given = m.a.normal_stiffness > 0.0 && m.b.normal_stiffness > 0.0;
    return {m.mu_s, given ? m.mean(&MaterialSpec::normal_stiffness) : 0.0,
            given ? 0.0 : 4.0 / 3.0 * m.e_star * 0.1, linear_gamma_for_restitution(m.restitution)};
  }
  template <class T, class C>
  [[gnu::always_inline]] static ContactForceT<T> evaluate(const C& c, const KinematicsT<T>& k,
                                                          const History<T>& old, History<T>& h,
                                                          double dt) {
    ContactForceT<T> out;
    const T k_n = c.kn_const + c.kn_per_radius * k.r_eff;
    const T f_el = k_n * k.delta;
    const T f_n = vmax(T(0.0), f_el + 2.0 * c.gamma * vsqrt(k_n * k.m_eff) * k.v_n);
    out.f_n = f_n;
    out.f_el = f_el;
    out.k_n = k_n;
    out.dissipated = (f_n - f_el) * k.v_n * dt;
    out.elastic = 0.5 * f_el * k.delta;
    out.strain = out.elastic;
    const T k_t = (2.0 / 7.0) * k_n;  // constant over the contact: k_old / k_new = 1
    tangential_spring(k_t, T(1.0), T(2.0 * c.gamma * vsqrt(k_t * k.m_eff)), c.mu_s, f_n, k.v_t,
                      k.v_t_step, dt, old[0], h[0], out);
    return out;
  }
  static double normal_stiffness(const Coeffs<double>& c, double r_eff, double) {
    return c.kn_const + c.kn_per_radius * r_eff;
  }
  // Constant stiffness: the whole 1/2 k_t xi^2 is released at once when the contact ends.
  static double spring_energy(const Coeffs<double>& c, double r_eff, double delta,
                              const double* h) {
    return 0.5 * (2.0 / 7.0) * normal_stiffness(c, r_eff, delta) * h[0] * h[0];
  }
};

// ---------------------------------------------------------------------------------------------
// Rolling models

// No rolling resistance: nothing is computed, nothing stored.
struct RollingNone : NoHistory {
  static constexpr RollingModelKind kKind = RollingModelKind::kNone;
  static constexpr bool kActive = false;
  static constexpr bool kNeedsInertia = false;
  template <class V>
  struct Coeffs {
    template <class S>
    static auto tie(S&) {
      return std::tie();
    }
  };
  static Coeffs<double> coeffs(const MaterialPair&, double) { return {}; }
  static double spring_energy(const Coeffs<double>&, double, double, const double*) { return 0.0; }
  template <class T, class C>
  [[gnu::always_inline]] static RollingTorqueT<T> evaluate(const C&, const KinematicsT<T>&,
                                                           const ContactForceT<T>&,
                                                           const History<T>&, History<T>&, double) {
    return {};
  }
};

// Constant directional torque (T16; Ai et al. 2011 model A): M = -mu_r F_n R* sign(w_rel).
struct RollingConstant : NoHistory {
  static constexpr RollingModelKind kKind = RollingModelKind::kConstant;
  static constexpr bool kActive = true;
  static constexpr bool kNeedsInertia = false;
  template <class V>
  struct Coeffs {
    V mu_r{};
    template <class S>
    static auto tie(S& c) {
      return std::tie(c.mu_r);
    }
  };
  static Coeffs<double> coeffs(const MaterialPair& m, double) { return {m.mu_r}; }
  static double spring_energy(const Coeffs<double>&, double, double, const double*) { return 0.0; }
  template <class T, class C>
  [[gnu::always_inline]] static RollingTorqueT<T> evaluate(const C& c, const KinematicsT<T>& k,
                                                           const ContactForceT<T>& cf,
                                                           const History<T>&, History<T>&,
                                                           double dt) {
    const T m = -c.mu_r * cf.f_n * k.r_eff * vsign(k.omega_rel);
    return {m, -m * k.omega_rel * dt, T(0.0)};
  }
};

// Elastic-plastic spring-dashpot (Ai et al. 2011 model C):
//   k_r = 2.25 k_n mu_r^2 R*^2, M_k += -k_r w_rel dt, |M_k| <= M_max = mu_r R* F_n,
//   M_d = -eta_r 2 sqrt(I_r k_r) w_rel while |M_k| < M_max (off at full mobilisation), and
//   |M_k + M_d| <= M_max: the dashpot cannot push the torque past the cap either.
// eta_r is `contact.rolling_damping`. Dissipation as in tangential_spring: the work of the
// whole torque on the rolling speed minus the change of the spring's energy M_k^2 / (2 k_r),
// plus the stiffness change at constant torque, M^2 / 2 (1 / k_old - 1 / k_new).
struct RollingEpsd {
  static constexpr RollingModelKind kKind = RollingModelKind::kEpsd;
  static constexpr bool kActive = true;
  static constexpr bool kNeedsInertia = true;
  static constexpr std::array<HistorySlot, 1> kHistory{
      {{"m_roll", "N m", "rolling spring torque"}}};
  template <class T>
  using History = HistoryArray<T, kHistory.size()>;
  template <class V>
  struct Coeffs {
    V mu_r{};
    V eta{};  // rolling dashpot damping ratio eta_r
    template <class S>
    static auto tie(S& c) {
      return std::tie(c.mu_r, c.eta);
    }
  };
  static Coeffs<double> coeffs(const MaterialPair& m, double rolling_damping) {
    return {m.mu_r, rolling_damping};
  }
  // M^2 / (2 k_r) at the law's normal stiffness k_n.
  static double spring_energy(const Coeffs<double>& c, double k_n, double r_eff, const double* h) {
    const double k_r = 2.25 * k_n * c.mu_r * c.mu_r * r_eff * r_eff;
    return k_r > 0.0 ? 0.5 * h[0] * h[0] / k_r : 0.0;
  }
  template <class T, class C>
  [[gnu::always_inline]] static RollingTorqueT<T> evaluate(const C& c, const KinematicsT<T>& k,
                                                           const ContactForceT<T>& cf,
                                                           const History<T>& old, History<T>& h,
                                                           double dt) {
    const T k_r = 2.25 * cf.k_n * c.mu_r * c.mu_r * k.r_eff * k.r_eff;
    const auto active = k_r > 0.0;  // mu_r = 0: no rolling spring at all
    const T m_max = c.mu_r * k.r_eff * cf.f_n;
    const T m_old = old[0];
    const T m_k = m_old - k_r * k.omega_rel_step * dt;
    const T half_compliance = 0.5 / k_r;
    // M^2 / 2 (1 / k_old - 1 / k_new); a new contact (k_old = 0) has no rolling torque yet.
    const T stiffness_change =
        select(cf.k_prev_ratio > 0.0,
               half_compliance * m_old * m_old * (1.0 / cf.k_prev_ratio - 1.0), T(0.0));
    // Full mobilisation: plastic rolling at the cap, no dashpot.
    const auto full = vabs(m_k) >= m_max;
    const T m_full = vcopysign(m_max, m_k);
    // Elastic: spring plus dashpot, the sum capped too.
    const T c_r = c.eta * 2.0 * vsqrt(k.i_eff * k_r);
    const T m = m_k - c_r * k.omega_rel;
    const T m_capped = vcopysign(m_max, m);
    const T torque = select(full, m_full, select(vabs(m) > m_max, m_capped, m));
    const T spring = select(full, m_full, m_k);
    h[0] = select(active, spring, T(0.0));
    RollingTorqueT<T> out;
    out.torque = select(active, torque, T(0.0));
    out.dissipated =
        select(active,
               -torque * k.omega_rel * dt - half_compliance * (spring * spring - m_old * m_old) +
                   stiffness_change,
               T(0.0));
    out.elastic = select(active, half_compliance * spring * spring, T(0.0));
    return out;
  }
};

// ---------------------------------------------------------------------------------------------
// The registries: the kernel is instantiated for every (law, rolling model) listed here and the
// scene's pair is picked at setup by kKind (contact_engine.cpp, make_contact_kernel).
using ContactLaws = std::tuple<HertzMindlin, ThesisModel, LinearModel>;
using RollingModels = std::tuple<RollingNone, RollingConstant, RollingEpsd>;

// ---------------------------------------------------------------------------------------------
// Trackers: what a contact records for models outside the force law.

struct TrackNone : NoHistory {
  static constexpr bool kExcludes = false;
  template <class T>
  [[gnu::always_inline]] static void evaluate(const ContactForceT<T>&, const History<T>&,
                                              History<T>&) {}
};

// The largest strain energy of the contact so far (the breakage test reads it at the peak or
// end of the contact, docs/models.md, grinding).
struct TrackPeakEnergy {
  static constexpr bool kExcludes = false;
  static constexpr std::array<HistorySlot, 1> kHistory{
      {{"peak_energy", "J", "largest normal strain energy of the contact so far"}}};
  template <class T>
  using History = HistoryArray<T, kHistory.size()>;
  template <class T>
  [[gnu::always_inline]] static void evaluate(const ContactForceT<T>& cf, const History<T>& old,
                                              History<T>& h) {
    h[0] = vmax(old[0], cf.strain);
  }
};

// Breakage (docs/models.md, "Grinding"): the peak strain energy, the energy
// at the end of the step (the test runs when it has fallen below the peak: core/mill/grinding.cpp),
// the peak level already tested, and the birth overlap: bodies that overlapped when one of them was
// born (a fragment inside its parent's circle) must not repel explosively (thesis), nor pass
// through each other. The contact acts on the overlap beyond the one at birth, delta - delta_0, and
// delta_0 follows the overlap down as the bodies separate, to 0 when they part (then the kernel
// clears the history as for every contact that ends). A contact born marked (delta_0 < 0,
// Grinding::exclude_births) takes its overlap at the first evaluation, the birth state.
struct TrackBreakage {
  static constexpr bool kExcludes = true;
  static constexpr std::size_t kPeak = 0, kEnergy = 1, kTested = 2, kBirthOverlap = 3;
  static constexpr std::array<HistorySlot, 4> kHistory{
      {{"peak_energy", "J", "largest normal strain energy of the contact so far"},
       {"energy", "J", "normal strain energy at the end of the last step"},
       {"tested", "J", "the peak energy already tested for breakage"},
       {"birth_overlap", "m", "overlap at a birth, ignored; follows the overlap down to 0"}}};
  template <class T>
  using History = HistoryArray<T, kHistory.size()>;
  template <class T>
  [[gnu::always_inline]] static void evaluate(const ContactForceT<T>& cf, const History<T>& old,
                                              History<T>& h) {
    h[kPeak] = vmax(old[kPeak], cf.strain);
    h[kEnergy] = cf.strain;
    h[kTested] = old[kTested];
  }
  // A contact past its peak, the peak above the level already tested: its breakage test is due
  // (core/mill/grinding.hpp).
  static bool test_due(double peak, double energy, double tested) {
    return energy < peak && peak > tested;
  }
};

// ---------------------------------------------------------------------------------------------
// Steppers: the speeds over a step that advance the tangential and rolling springs and give the
// overlap at the step's start (the stiffness change). They must match the integrator's own
// update of the positions, or the springs integrate at a lower order than the bodies.

// Velocity Verlet: the law sees the half-step velocities, which are the step's mean.
struct StepAsSeen : NoHistory {
  template <class T>
  [[gnu::always_inline]] static void prepare(KinematicsT<T>& k, const History<T>&, History<T>&) {
    k.v_n_step = k.v_n;
    k.v_t_step = k.v_t;
    k.omega_rel_step = k.omega_rel;
  }
};

// The iterative scheme: the law sees the end-of-step velocities; the step's mean is taken with
// the speeds the contact had at the end of the previous step (trapezoid rule, second order like
// the scheme's x1 = x0 + dt (v0 + v1) / 2 + O(dt^3)). In a contact's first step the end speeds
// are used (it began within the step).
struct StepTrapezoid {
  static constexpr std::array<HistorySlot, 4> kHistory{
      {{"v_n_end", "m/s", "normal speed at the end of the last step"},
       {"v_t_end", "m/s", "sliding speed at the end of the last step"},
       {"omega_rel_end", "rad/s", "relative spin at the end of the last step"},
       {"stepped", "1", "1 once the contact has lasted a whole step"}}};
  template <class T>
  using History = HistoryArray<T, kHistory.size()>;
  template <class T>
  [[gnu::always_inline]] static void prepare(KinematicsT<T>& k, const History<T>& old,
                                             History<T>& h) {
    const auto stepped = old[3] > 0.5;
    k.v_n_step = select(stepped, 0.5 * (old[0] + k.v_n), k.v_n);
    k.v_t_step = select(stepped, 0.5 * (old[1] + k.v_t), k.v_t);
    k.omega_rel_step = select(stepped, 0.5 * (old[2] + k.omega_rel), k.omega_rel);
    h = {k.v_n, k.v_t, k.omega_rel, T(1.0)};
  }
};

// ---------------------------------------------------------------------------------------------
// The composed model: one law, one rolling model, one tracker, one stepper.

template <class T, class Law, class Rolling, class Tracker, class Stepper>
struct ContactHistoryT {
  typename Law::template History<T> law{};
  typename Rolling::template History<T> rolling{};
  typename Tracker::template History<T> tracker{};
  typename Stepper::template History<T> stepper{};
};

template <class T>
struct ContactResponseT {
  ContactForceT<T> law;
  RollingTorqueT<T> rolling;
  T birth_overlap = T(0.0);  // m of the overlap ignored (trackers with kExcludes only)
};

template <class LawT, class RollingT, class TrackerT, class StepperT = StepAsSeen>
struct ContactModel {
  using Law = LawT;
  using Rolling = RollingT;
  using Tracker = TrackerT;
  using Stepper = StepperT;
  static constexpr std::size_t kLawSlots = Law::kHistory.size();
  static constexpr std::size_t kRollingSlots = Rolling::kHistory.size();
  static constexpr std::size_t kHistoryWidth =
      kLawSlots + kRollingSlots + Tracker::kHistory.size() + Stepper::kHistory.size();
  template <class T>
  using History = ContactHistoryT<T, Law, Rolling, Tracker, Stepper>;
  template <class V>
  struct Coeffs {
    typename Law::template Coeffs<V> law;
    typename Rolling::template Coeffs<V> rolling;
  };

  // The declared slots, law first, then rolling, tracker and stepper: the order of the values in
  // the neighbour lists and in HistoryRecords.
  static std::vector<HistorySlot> history_slots() {
    std::vector<HistorySlot> out;
    out.reserve(kHistoryWidth);
    for (const HistorySlot& s : Law::kHistory) out.push_back(s);
    for (const HistorySlot& s : Rolling::kHistory) out.push_back(s);
    for (const HistorySlot& s : Tracker::kHistory) out.push_back(s);
    for (const HistorySlot& s : Stepper::kHistory) out.push_back(s);
    return out;
  }
  static Coeffs<double> coeffs(const MaterialPair& m, const ContactSpec& spec) {
    return {Law::coeffs(m), Rolling::coeffs(m, spec.rolling_damping)};
  }
  template <class Index>
  [[gnu::always_inline]] static Coeffs<Pack> gather(const Coeffs<double>* table, Index index) {
    using LawC = typename Law::template Coeffs<double>;
    using RollC = typename Rolling::template Coeffs<double>;
    return {gather_coeffs<Law::template Coeffs>(
                [&](auto l) -> const LawC& { return table[index(l)].law; }),
            gather_coeffs<Rolling::template Coeffs>(
                [&](auto l) -> const RollC& { return table[index(l)].rolling; })};
  }
  // The energy the springs of a contact hold at overlap delta, with the history `h` (its slots
  // in declaration order): what the contact releases when it ends.
  static double spring_energy(const Coeffs<double>& c, double r_eff, double delta,
                              const double* h) {
    return Law::spring_energy(c.law, r_eff, delta, h) +
           Rolling::spring_energy(c.rolling, Law::normal_stiffness(c.law, r_eff, delta), r_eff,
                                  h + kLawSlots);
  }
  static Coeffs<Pack> broadcast(const Coeffs<double>& c) {
    return {broadcast_coeffs<Law::template Coeffs>(c.law),
            broadcast_coeffs<Rolling::template Coeffs>(c.rolling)};
  }

  // One contact (or one per lane): the stepper's speeds, the law, then the rolling model on the
  // law's normal force, then the tracker on both. Shared by particle-particle and particle-wall
  // contacts.
  template <class T, class C>
  [[gnu::always_inline]] static ContactResponseT<T> evaluate(const C& c, KinematicsT<T> kin,
                                                             const History<T>& old, History<T>& h,
                                                             double dt) {
    ContactResponseT<T> out;
    if constexpr (Tracker::kExcludes) {
      // The overlap at birth is ignored (TrackBreakage); it follows the overlap down.
      const T marked = old.tracker[Tracker::kBirthOverlap];
      const T d0 = vmin(select(marked < 0.0, kin.delta, marked), kin.delta);
      const auto beyond = kin.delta - d0 > 0.0;
      kin.delta = select(beyond, kin.delta - d0, T(1e-300));
      respond_all(c, kin, old, h, dt, out);
      if (any_of(!beyond)) mask(!beyond, out, h);
      out.birth_overlap = d0;
      h.tracker[Tracker::kBirthOverlap] = d0;
    } else {
      respond_all(c, kin, old, h, dt, out);
    }
    return out;
  }

  template <class T, class C>
  [[gnu::always_inline]] static void respond_all(const C& c, KinematicsT<T>& kin,
                                                 const History<T>& old, History<T>& h, double dt,
                                                 ContactResponseT<T>& out) {
    Stepper::prepare(kin, old.stepper, h.stepper);
    out.law = Law::evaluate(c.law, kin, old.law, h.law, dt);
    if constexpr (Rolling::kActive)
      out.rolling = Rolling::evaluate(c.rolling, kin, out.law, old.rolling, h.rolling, dt);
    Tracker::evaluate(out.law, old.tracker, h.tracker);
  }

  // A contact not compressed beyond its birth overlap: no force, no energy, no spring history.
  template <class T, class M>
  [[gnu::always_inline]] static void mask(const M& off, ContactResponseT<T>& out, History<T>& h) {
    const T zero(0.0);
    ContactForceT<T>& f = out.law;
    for (T* x : {&f.f_n, &f.f_t, &f.k_n, &f.dissipated, &f.elastic, &f.strain, &f.f_el})
      *x = select(off, zero, *x);
    RollingTorqueT<T>& r = out.rolling;
    for (T* x : {&r.torque, &r.dissipated, &r.elastic}) *x = select(off, zero, *x);
    for (T& x : h.law) x = select(off, zero, x);
    for (T& x : h.rolling) x = select(off, zero, x);
    for (T& x : h.stepper) x = select(off, zero, x);
    h.tracker[Tracker::kEnergy] = select(off, zero, h.tracker[Tracker::kEnergy]);
  }
};

}  // namespace dem2d
