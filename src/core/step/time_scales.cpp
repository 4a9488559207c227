#include "core/step/time_scales.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "core/contact/materials.hpp"
#include "core/geometry/walls.hpp"
#include "core/shape/disc.hpp"

namespace dem2d {

double steps_per_contact_for(double restitution) {
  if (restitution >= 1.0) return 20.0;
  const double x = -std::log(restitution) / std::log(2.0);
  return std::max(20.0, 50.0 * std::pow(x, 1.77));
}

namespace {

// Largest expected closing speeds. Against a wall: the drum's rim speed twice (a ball thrown
// off the shell meets the shell coming the other way) plus free fall across the drum; without
// a drum, the fastest initial particle plus the walls' speeds plus free fall across the
// particles' extent. Between two particles: two of the fastest head-on (with a drum, a ball
// riding the shell at rim speed meets one thrown at rim speed), plus free fall.
struct ClosingSpeeds {
  double wall = 0.0, pair = 0.0;
};
ClosingSpeeds closing_speeds(const Scene& scene, const ParticleStore& p) {
  double v_max = 0.0, y_lo = std::numeric_limits<double>::max(), y_hi = -y_lo;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    v_max = std::max(v_max, norm(p.vel[k]) + std::abs(p.omega[k]) * p.radius[k]);
    y_lo = std::min(y_lo, p.pos[k].y - p.radius[k]);
    y_hi = std::max(y_hi, p.pos[k].y + p.radius[k]);
  }
  double fall = p.n_owned() > 0 ? y_hi - y_lo : 0.0;
  double v_part = v_max;
  for (const WallSpec& w : scene.walls) {
    fall = std::max(fall, y_hi - std::min(w.from.y, w.to.y));
    v_max += norm(w.velocity);
  }
  if (scene.drum.present) {
    fall = 2.0 * scene.drum.radius;
    v_max = std::max(v_max, 2.0 * std::abs(scene.drum.speed) * scene.drum.radius);
    v_part = std::max(v_part, std::abs(scene.drum.speed) * scene.drum.radius);
  }
  const double free_fall = std::sqrt(2.0 * norm(scene.run.gravity) * std::max(fall, 0.0));
  return {std::max(v_max + free_fall, 1e-3), std::max(2.0 * v_part + free_fall, 1e-3)};
}

// Hertz contact time t_c = 2.868 (m*^2 / (R* E*^2 v))^(1/5) (Johnson 1985).
double contact_time(double m_eff, double r_eff, double e_star, double v) {
  return 2.868 * std::pow(m_eff * m_eff / (r_eff * e_star * e_star * v), 0.2);
}

// "a against b" or "a against the walls of b" (b: a wall material only).
std::string pair_name(const Scene& scene, std::size_t a, std::size_t b, bool wall) {
  return scene.materials[a].name + (wall ? " against a wall of " : " against ") +
         scene.materials[b].name;
}

// Smallest restitution among the pairs of materials present (particles and walls), and the
// pair. The thesis law's damping ratio is converted through its hertz-mindlin equivalent (T22).
std::pair<double, std::string> smallest_restitution(const Scene& scene, const ParticleStore& p,
                                                    const PairTable& table) {
  const std::size_t nm = scene.materials.size();
  std::vector<char> used(nm, 0);
  for (std::size_t k = 0; k < p.n_owned(); ++k) used[p.material[k]] = 1;
  const Walls walls(scene);
  std::vector<char> touched(nm, 0);
  for (const WallElement& e : walls.elements()) touched[e.material] = 1;
  double e_min = 1.0;
  std::string which;
  for (std::size_t a = 0; a < nm; ++a) {
    if (!used[a]) continue;
    for (std::size_t b = 0; b < nm; ++b) {
      if (!used[b] && !touched[b]) continue;
      const MaterialPair& c = table(static_cast<int>(a), static_cast<int>(b));
      double e = c.restitution;
      if (scene.contact.model == ContactModelKind::kThesis)
        e = restitution_hertz_clamped(-c.zeta_n / std::sqrt(5.0 / 6.0));
      if (e < e_min || which.empty()) which = pair_name(scene, a, b, !used[b]);
      e_min = std::min(e_min, e);
    }
  }
  return {e_min, which};
}

}  // namespace

TimeScales time_scales(const Scene& scene, const ParticleStore& p) {
  TimeScales ts;
  const ClosingSpeeds v = closing_speeds(scene, p);
  ts.impact_speed = std::max(v.wall, v.pair);
  ts.rayleigh = std::numeric_limits<double>::max();
  ts.hertz = std::numeric_limits<double>::max();
  const PairTable table(scene);
  // Per material: the smallest radius present (the shortest contact time: t_c ~ r).
  const std::size_t nm = scene.materials.size();
  // The materials of the walls (a material no wall and no particle has, e.g. the shell's for its
  // finite elements alone, sets no contact time).
  std::vector<char> wall_material(nm, 0);
  const Walls walls(scene);
  for (const WallElement& e : walls.elements()) wall_material[e.material] = 1;
  std::vector<double> r_min(nm, std::numeric_limits<double>::max());
  // A shaped particle counts as the sphere of its smaller semi-axis (lighter than it, so its
  // contact times are shorter; its curvature radii are not looked at).
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    r_min[p.material[k]] =
        std::min(r_min[p.material[k]],
                 p.shaped() ? std::min((*p.semi_a())[k], (*p.semi_b())[k]) : p.radius[k]);
  // Ore scenes: the smallest particle the run can make, from the start (the dt stays safe as
  // fragments get small): a fragment of the smallest breakable particle, and the smallest fed.
  if (scene.breakage.present) {
    const int m = find_material(scene, scene.breakage.material);
    const double smallest = smallest_fragment_radius(scene.breakage);
    if (m >= 0 && r_min[m] != std::numeric_limits<double>::max())
      r_min[m] = std::min(r_min[m], smallest);
  }
  if (scene.feed.present) {
    const int m = find_material(scene, scene.feed.material);
    if (m >= 0) r_min[m] = std::min(r_min[m], scene.feed.radius_min);
  }
  for (std::size_t a = 0; a < nm; ++a) {
    if (r_min[a] == std::numeric_limits<double>::max()) continue;
    const MaterialSpec& m = scene.materials[a];
    ts.rayleigh =
        std::min(ts.rayleigh, std::numbers::pi * r_min[a] * std::sqrt(m.density / m.shear_modulus) /
                                  (0.1631 * m.poisson_ratio + 0.8766));
    const double mass_a = Disc::mass(r_min[a], m.density);
    for (std::size_t b = 0; b < nm; ++b) {
      const double e_star = table(static_cast<int>(a), static_cast<int>(b)).e_star;
      const auto shorter = [&](double t, bool wall) {
        if (t < ts.hertz) ts.hertz_pair = pair_name(scene, a, b, wall);
        ts.hertz = std::min(ts.hertz, t);
      };
      // The smallest sphere against a wall of material b (m* = m, R* = r).
      if (wall_material[b]) shorter(contact_time(mass_a, r_min[a], e_star, v.wall), true);
      // Against the smallest sphere of material b: the pair's reduced mass and radius.
      if (r_min[b] == std::numeric_limits<double>::max()) continue;
      const double mass_b = Disc::mass(r_min[b], scene.materials[b].density);
      shorter(contact_time(mass_a * mass_b / (mass_a + mass_b),
                           r_min[a] * r_min[b] / (r_min[a] + r_min[b]), e_star, v.pair),
              false);
    }
  }
  if (ts.rayleigh == std::numeric_limits<double>::max()) ts.rayleigh = ts.hertz = 1.0;
  std::tie(ts.restitution_min, ts.restitution_pair) = smallest_restitution(scene, p, table);
  ts.steps_per_contact = steps_per_contact_for(ts.restitution_min);
  const double bound = std::min(ts.rayleigh, ts.hertz);
  ts.safe_dt = std::min(scene.run.dt_safety * ts.rayleigh, ts.hertz / ts.steps_per_contact);
  ts.limit_dt = 0.5 * bound;
  return ts;
}

}  // namespace dem2d
