#include "core/time_scales.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "core/materials.hpp"
#include "core/walls.hpp"

namespace dem2d {

double steps_per_contact_for(double restitution) {
  if (restitution >= 1.0) return 20.0;
  const double x = -std::log(restitution) / std::log(2.0);
  return std::max(20.0, 50.0 * std::pow(x, 1.77));
}

TimeScales time_scales(const Scene& scene, const ParticleStore& p) {
  TimeScales ts;
  const double g = norm(scene.run.gravity);
  // Largest expected impact speed: the drum's rim speed twice (a ball thrown off the shell
  // meets the shell coming the other way) plus free fall across the drum; without a drum,
  // the fastest initial particle plus free fall across the particles' extent.
  double v_max = 0.0, y_lo = std::numeric_limits<double>::max(), y_hi = -y_lo;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    v_max = std::max(v_max, norm(p.vel[k]) + std::abs(p.omega[k]) * p.radius[k]);
    y_lo = std::min(y_lo, p.pos[k].y - p.radius[k]);
    y_hi = std::max(y_hi, p.pos[k].y + p.radius[k]);
  }
  double fall = p.n_owned() > 0 ? y_hi - y_lo : 0.0;
  for (const WallSpec& w : scene.walls) {
    fall = std::max(fall, y_hi - std::min(w.from.y, w.to.y));
    v_max += norm(w.velocity);
  }
  if (scene.drum.present) {
    fall = 2.0 * scene.drum.radius;
    v_max = std::max(v_max, 2.0 * std::abs(scene.drum.speed) * scene.drum.radius);
  }
  ts.impact_speed = std::max(v_max + std::sqrt(2.0 * g * std::max(fall, 0.0)), 1e-3);

  ts.rayleigh = std::numeric_limits<double>::max();
  ts.hertz = std::numeric_limits<double>::max();
  const PairTable table(scene);
  // Per material: the smallest radius and mass present.
  const std::size_t nm = scene.materials.size();
  std::vector<double> r_min(nm, std::numeric_limits<double>::max());
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    r_min[p.material[k]] = std::min(r_min[p.material[k]], p.radius[k]);
  for (std::size_t a = 0; a < nm; ++a) {
    if (r_min[a] == std::numeric_limits<double>::max()) continue;
    const MaterialSpec& m = scene.materials[a];
    ts.rayleigh =
        std::min(ts.rayleigh, std::numbers::pi * r_min[a] * std::sqrt(m.density / m.shear_modulus) /
                                  (0.1631 * m.poisson_ratio + 0.8766));
    // Hertz contact time of the smallest sphere against a wall of the stiffest material
    // (m* = m, R* = r): t_c = 2.868 (m*^2 / (R* E*^2 v))^(1/5).
    for (std::size_t b = 0; b < nm; ++b) {
      const double mass = ParticleStore::sphere_mass(r_min[a], m.density);
      const double e_star = table(static_cast<int>(a), static_cast<int>(b)).e_star;
      const double tc =
          2.868 * std::pow(mass * mass / (r_min[a] * e_star * e_star * ts.impact_speed), 0.2);
      ts.hertz = std::min(ts.hertz, tc);
    }
  }
  if (ts.rayleigh == std::numeric_limits<double>::max()) ts.rayleigh = ts.hertz = 1.0;
  // Smallest restitution among the pairs of materials present (particles and walls). The
  // thesis law's damping ratio is converted through its hertz-mindlin equivalent (T22).
  std::vector<char> used(nm, 0);
  for (std::size_t k = 0; k < p.n_owned(); ++k) used[p.material[k]] = 1;
  const Walls walls(scene);
  std::vector<char> touched(nm, 0);
  for (const WallElement& e : walls.elements()) touched[e.material] = 1;
  for (std::size_t a = 0; a < nm; ++a) {
    if (!used[a]) continue;
    for (std::size_t b = 0; b < nm; ++b) {
      if (!used[b] && !touched[b]) continue;
      const MaterialPair& c = table(static_cast<int>(a), static_cast<int>(b));
      double e = c.restitution;
      if (scene.contact.model == ContactModelKind::kThesis)
        e = restitution_hertz_clamped(-c.zeta_n / std::sqrt(5.0 / 6.0));
      ts.restitution_min = std::min(ts.restitution_min, e);
    }
  }
  ts.steps_per_contact = steps_per_contact_for(ts.restitution_min);
  const double bound = std::min(ts.rayleigh, ts.hertz);
  ts.safe_dt = std::min(scene.run.dt_safety * ts.rayleigh, ts.hertz / ts.steps_per_contact);
  ts.limit_dt = 0.5 * bound;
  return ts;
}

}  // namespace dem2d
