#include "core/contact/materials.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <numbers>

namespace dem2d {

namespace {

// One normal contact in dimensionless form, clamped at zero force:
//   x'' = -max(0, x^p + eta x^q x'),  x(0) = 0, x'(0) = 1,
// integrated with classical RK4 until the bodies separate (x back to 0); returns -x'.
// Hertz with the hertz-mindlin damping: x^(3/2) + eta x^(1/4) x', eta = sqrt(5) |beta|.
// Linear spring-dashpot: x + eta x', eta = 2 gamma.
// The restitution of both laws is independent of the impact speed, so this one number is it.
template <class Force>
double clamped_restitution(Force force) {
  auto accel = [&](double x, double v) { return x <= 0.0 ? 0.0 : -std::max(0.0, force(x, v)); };
  double x = 0.0, v = 1.0;
  const double h = 1.0e-4;  // the contact lasts about 3.2 time units
  for (int k = 0; k < 100000000; ++k) {
    const double k1x = v, k1v = accel(x, v);
    const double k2x = v + 0.5 * h * k1v, k2v = accel(x + 0.5 * h * k1x, v + 0.5 * h * k1v);
    const double k3x = v + 0.5 * h * k2v, k3v = accel(x + 0.5 * h * k2x, v + 0.5 * h * k2v);
    const double k4x = v + h * k3v, k4v = accel(x + h * k3x, v + h * k3v);
    const double xn = x + h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
    const double vn = v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
    if (xn <= 0.0 && k > 0) return -vn;  // separated within this step (force ~ 0 there)
    x = xn;
    v = vn;
  }
  return -v;
}

double hertz_clamped(double eta) {
  return clamped_restitution([eta](double x, double v) {
    const double s = std::sqrt(x);
    return x * s + eta * std::sqrt(s) * v;
  });
}

double linear_clamped(double eta) {
  return clamped_restitution([eta](double x, double v) { return x + eta * v; });
}

// Invert a decreasing map damping -> restitution by bisection on [0, hi].
template <class F>
double invert_restitution(double e, F restitution_of, double hi) {
  if (e >= 1.0) return 0.0;
  double lo = 0.0;
  while (restitution_of(hi) > e) hi *= 2.0;
  for (int it = 0; it < 60 && hi - lo > 1e-9 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (restitution_of(mid) > e ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// f(e), computed once per value of e (each inversion costs tens of milliseconds; a scene asks
// for the same few restitutions again and again). One cache per function.
template <class F>
double cached(std::map<double, double>& cache, std::mutex& mutex, double e, F f) {
  std::lock_guard<std::mutex> lock(mutex);
  if (auto it = cache.find(e); it != cache.end()) return it->second;
  return cache[e] = f(e);
}

double mean_or(const std::optional<double>& v, double a, double b) {
  return v ? *v : 0.5 * (a + b);
}

}  // namespace

double restitution_hertz_clamped(double beta) {
  return hertz_clamped(std::sqrt(5.0) * std::abs(beta));
}

double hertz_beta_for_restitution(double e) {
  static std::mutex mutex;
  static std::map<double, double> cache;
  return cached(cache, mutex, e, [](double x) {
    return -invert_restitution(x, hertz_clamped, 4.0) / std::sqrt(5.0);
  });
}

double restitution_linear_clamped(double gamma) { return linear_clamped(2.0 * gamma); }

double linear_gamma_for_restitution(double e) {
  static std::mutex mutex;
  static std::map<double, double> cache;
  return cached(cache, mutex, e,
                [](double x) { return 0.5 * invert_restitution(x, linear_clamped, 4.0); });
}

PairTable::PairTable(const Scene& scene) : n_(static_cast<int>(scene.materials.size())) {
  table_.resize(static_cast<std::size_t>(n_) * n_);
  for (int a = 0; a < n_; ++a) {
    for (int b = 0; b < n_; ++b) {
      const MaterialSpec& ma = scene.materials[a];
      const MaterialSpec& mb = scene.materials[b];
      const InteractionSpec* inter = nullptr;
      for (const InteractionSpec& s : scene.interactions) {
        if ((s.material_a == ma.name && s.material_b == mb.name) ||
            (s.material_a == mb.name && s.material_b == ma.name))
          inter = &s;
      }
      const InteractionSpec none;
      const InteractionSpec& in = inter ? *inter : none;
      MaterialPair c;
      c.a = ma;
      c.b = mb;
      const double nu_a = ma.poisson_ratio, nu_b = mb.poisson_ratio;
      c.e_star =
          1.0 / ((1 - nu_a * nu_a) / ma.youngs_modulus + (1 - nu_b * nu_b) / mb.youngs_modulus);
      c.g_star = 1.0 / (2 * (2 - nu_a) * (1 + nu_a) / ma.youngs_modulus +
                        2 * (2 - nu_b) * (1 + nu_b) / mb.youngs_modulus);
      c.restitution = mean_or(in.restitution, ma.restitution, mb.restitution);
      c.mu_s = mean_or(in.sliding_friction, ma.sliding_friction, mb.sliding_friction);
      c.mu_r = mean_or(in.rolling_friction, ma.rolling_friction, mb.rolling_friction);
      c.zeta_n = mean_or(in.damping_normal, ma.damping_normal, mb.damping_normal);
      c.zeta_t = mean_or(in.damping_tangential, ma.damping_tangential, mb.damping_tangential);
      table_[a * n_ + b] = c;
    }
  }
}

int find_material(const Scene& scene, const std::string& name) {
  for (std::size_t k = 0; k < scene.materials.size(); ++k)
    if (scene.materials[k].name == name) return static_cast<int>(k);
  return -1;
}

}  // namespace dem2d
