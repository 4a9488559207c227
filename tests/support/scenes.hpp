// Scene parts the tests build again and again: a material from its elastic constants, a rigid
// wall's material, a fixed-dt scene for single contacts, a ball, a wall segment, a head-on pair
// and a ball resting on a steel floor.
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "core/base/scene.hpp"

namespace dem2d::testing_support {

// A material with G = E / (2 (1 + nu)) set explicitly (the deck parser would derive it).
inline MaterialSpec make_material(const std::string& name, double density, double young, double nu,
                                  double restitution, double mu_s, double mu_r = 0.0) {
  MaterialSpec m;
  m.name = name;
  m.density = density;
  m.youngs_modulus = young;
  m.poisson_ratio = nu;
  m.shear_modulus = young / (2.0 * (1.0 + nu));
  m.restitution = restitution;
  m.sliding_friction = mu_s;
  m.rolling_friction = mu_r;
  return m;
}

// A rigid wall's material "rigid": E = 1e30, so E* = E/(1 - nu^2) of the sphere alone; every
// other value (restitution, friction, density) is the ball's, so the pair takes the ball's.
inline MaterialSpec rigid_wall_material(const MaterialSpec& ball) {
  MaterialSpec m = ball;
  m.name = "rigid";
  m.youngs_modulus = 1e30;
  m.shear_modulus = 1e30 / (2.0 * (1.0 + m.poisson_ratio));
  return m;
}

// A scene for single contacts: `dt` fixed, the given contact law, no gravity unless given.
inline Scene contact_scene(const std::string& title, double dt, ContactModelKind model,
                           RollingModelKind rolling, Vec2 gravity = {0.0, 0.0}) {
  Scene s;
  s.title = title;
  s.run.dt_auto = false;
  s.run.dt = dt;
  s.run.gravity = gravity;
  s.contact.model = model;
  s.contact.rolling = rolling;
  return s;
}

inline ParticleSpec ball(const std::string& material, double r, Vec2 x, Vec2 v = {},
                         double spin = 0.0) {
  ParticleSpec p;
  p.material = material;
  p.radius = r;
  p.position = x;
  p.velocity = v;
  p.spin = spin;
  return p;
}

// A [[fill]] of `count` particles of `material`, radii uniform in [r_min, r_max], in `region`,
// at deck line 7 (for the messages tests read).
inline FillSpec fill_spec(const std::string& material, std::int64_t count, double r_min,
                          double r_max, FillRegion region) {
  FillSpec f;
  f.material = material;
  f.count = count;
  f.radius_min = r_min;
  f.radius_max = r_max;
  f.region = region;
  f.source_line = 7;
  return f;
}

inline WallSpec segment(Vec2 from, Vec2 to, const std::string& material, Vec2 velocity = {}) {
  WallSpec w;
  w.from = from;
  w.to = to;
  w.material = material;
  w.velocity = velocity;
  return w;
}

// Two `material` balls of radius r at (-x, 0) and (x, 0) approaching head-on at v each.
inline std::vector<ParticleSpec> head_on_pair(const std::string& material, double r, double x,
                                              double v) {
  return {ball(material, r, {-x, 0.0}, {v, 0.0}), ball(material, r, {x, 0.0}, {-v, 0.0})};
}

// A "steel" floor from (-1, 0) to (1, 0) and on it a "steel" ball of radius r at its Hertz
// overlap under g = 9.81 (rho 7800, E 2e11, nu 0.25: R* = r, E* = E / (2 (1 - nu^2))), moving
// at v.
inline void put_ball_on_steel_floor(Scene& s, double r, Vec2 v) {
  s.walls = {segment({-1.0, 0.0}, {1.0, 0.0}, "steel")};
  const double m = 4.0 / 3.0 * std::numbers::pi * r * r * r * 7800.0;
  const double e_star = 2.0e11 / (2.0 * (1.0 - 0.25 * 0.25));
  const double delta0 = std::pow(m * 9.81 / (4.0 / 3.0 * e_star * std::sqrt(r)), 2.0 / 3.0);
  s.particles.push_back(ball("steel", r, {0.0, r - delta0}, v));
}

}  // namespace dem2d::testing_support
