#include "core/mill/breakage_laws.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/shape/disc.hpp"

namespace dem2d {

double vogel_peukert_probability(double f_mat, double xw_min, double diameter, double w) {
  const double excess = w - xw_min / diameter;
  return excess > 0.0 ? -std::expm1(-f_mat * diameter * excess) : 0.0;
}

double t10_fraction(double a_percent, double b, double e_cs_kwh_per_t) {
  return -0.01 * a_percent * std::expm1(-b * e_cs_kwh_per_t);
}

double progeny_exponent(double t10) {
  // t10 -> 0: all the mass stays at the parent's size; the exponent is held finite.
  constexpr double kLargest = 1e3;
  if (!(t10 > 0.0)) return kLargest;
  return std::min(kLargest, std::log(t10) / std::log(0.1));
}

Progeny t10_progeny(double parent_radius, double density, double alpha, double fines_diameter) {
  Progeny out;
  out.alpha = alpha;
  const double big_x = 2.0 * parent_radius;
  const double mass = Disc::mass(parent_radius, density);
  const double q = std::pow(2.0, -0.25);
  const auto passing = [&](double x) { return std::pow(x / big_x, alpha); };
  double carry = 0.0, placed = 0.0;
  double hi = big_x;
  while (hi > fines_diameter && static_cast<int>(out.radii.size()) < kMaxFragments) {
    const double lo = std::max(hi * q, fines_diameter);
    const double d = std::sqrt(hi * lo);
    const double one = Disc::mass(0.5 * d, density);
    const double target = mass * (passing(hi) - passing(lo)) + carry;
    double n = std::floor(target / one);
    n = std::min(n, static_cast<double>(kMaxFragments - static_cast<int>(out.radii.size())));
    for (int k = 0; k < static_cast<int>(n); ++k) {
      out.radii.push_back(0.5 * d);
      placed += one;
    }
    carry = target - n * one;
    hi = lo;
  }
  out.fines_law_mass = mass * passing(std::min(fines_diameter, big_x));
  out.fines_mass = std::max(0.0, mass - placed);
  return out;
}

std::vector<Offset> fragment_offsets(double parent_radius, const std::vector<double>& radii,
                                     double turn) {
  const std::size_t n = radii.size();
  std::vector<Offset> o(n);
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  double m = 0.0, mx = 0.0, my = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double rho = (parent_radius - radii[k]) * std::sqrt((k + 0.5) / static_cast<double>(n));
    const double a = turn + golden * static_cast<double>(k);
    o[k] = {rho * std::cos(a), rho * std::sin(a)};
    const double mk = radii[k] * radii[k] * radii[k];  // mass / (4/3 pi rho): one density
    m += mk;
    mx += mk * o[k].x;
    my += mk * o[k].y;
  }
  if (n == 0 || m <= 0.0) return o;
  double spread = 0.0, own = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    o[k].x -= mx / m;
    o[k].y -= my / m;
    const double mk = radii[k] * radii[k] * radii[k];
    spread += mk * (o[k].x * o[k].x + o[k].y * o[k].y);
    own += 0.4 * mk * radii[k] * radii[k];
  }
  const double parent =
      0.4 * parent_radius * parent_radius * parent_radius * parent_radius * parent_radius;
  if (spread > 0.0 && own + spread > parent) {
    const double s = own < parent ? std::sqrt((parent - own) / spread) : 0.0;
    for (Offset& x : o) x = {s * x.x, s * x.y};
  }
  return o;
}

}  // namespace dem2d
