// Shared test fixtures: the thesis's steel (its Table 1) and its drum.
#pragma once

#include <cstdint>
#include <random>
#include <string>

#include "core/base/scene.hpp"
#include "core/step/diagnostics.hpp"
#include "support/scenes.hpp"

namespace dem2d::testing_support {

// Steel of the thesis's Table 1: rho 7800 kg/m^3, E 2e11 Pa, G 8e10 Pa (nu = 0.25),
// restitution 0.73 (= zeta_n 0.1 through T22), sliding friction 0.1, rolling friction 0.05.
inline MaterialSpec thesis_steel(double restitution = 0.73) {
  MaterialSpec m;
  m.name = "steel";
  m.density = 7800.0;
  m.youngs_modulus = 2.0e11;
  m.poisson_ratio = 0.25;
  m.shear_modulus = 8.0e10;  // = E / (2 (1 + nu))
  m.restitution = restitution;
  m.sliding_friction = 0.1;
  m.rolling_friction = 0.05;
  return m;
}

// The thesis drum (radius 2.5 m, `sides` = 0 for a circle) at `speed` rad/s reached in
// `ramp_time` s, with `balls` steel balls of radius 0.1 m filled from the bottom; dt "auto".
inline Scene thesis_drum_scene(int balls, double speed, int sides, double ramp_time = 0.5) {
  Scene s;
  s.deck_path = "test";
  s.materials.push_back(thesis_steel());
  s.run.dt_auto = true;
  s.drum.present = true;
  s.drum.radius = 2.5;
  s.drum.speed = speed;
  s.drum.ramp_time = ramp_time;
  s.drum.sides = sides;
  s.drum.material = "steel";
  FillSpec f;
  f.material = "steel";
  f.count = balls;
  f.radius_min = f.radius_max = 0.1;
  f.region = FillRegion::kBottom;
  s.fills.push_back(f);
  return s;
}

// The thesis drum (a circle, `speed` rad/s after a 0.1 s ramp) holding `count` steel bodies of
// bounding radius 0.1 m on a square grid from the bottom up (0.21 m apart), each an ellipse of
// semi-axes 0.1 and `aspect` 0.1 m at a random angle (seeded), or (!shaped) a disc of radius
// 0.1 m: the same scene for shapes and discs; each starts at a random velocity of up to 1 m/s
// per component, so that they collide from the start. dt fixed at 1e-5 s.
inline Scene shaped_drum_scene(int count, double aspect, double speed, bool shaped,
                               std::uint32_t seed = 7) {
  Scene s;
  s.title = shaped ? "ellipses in the thesis drum" : "discs in the thesis drum";
  s.deck_path = "test";
  s.materials.push_back(thesis_steel());
  s.run.dt_auto = false;
  s.run.dt = 1e-5;
  s.run.duration = 100.0;
  s.drum.present = true;
  s.drum.radius = 2.5;
  s.drum.speed = speed;
  s.drum.ramp_time = 0.1;
  s.drum.material = "steel";
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> turn(0.0, 3.14159265358979);
  const double r = 0.1, spacing = 0.21, inner = 2.5 - 1.05 * r;
  for (double y = -inner; y < inner && static_cast<int>(s.particles.size()) < count; y += spacing)
    for (double x = -inner; x < inner && static_cast<int>(s.particles.size()) < count;
         x += spacing) {
      if (x * x + y * y > inner * inner) continue;
      const double vx = 2.0 * turn(rng) / 3.14159265358979 - 1.0;
      const double vy = 2.0 * turn(rng) / 3.14159265358979 - 1.0;
      ParticleSpec p = ball("steel", r, {x, y}, {vx, vy});
      if (shaped) {
        p.semi_a = r;
        p.semi_b = aspect * r;
        p.angle = turn(rng);
      }
      s.particles.push_back(p);
    }
  return s;
}

// An open box of three `material` wall segments: the floor from (-half_width, 0) to
// (half_width, 0) and two sides up to `height`.
inline void add_open_box(Scene& s, double half_width, double height, const std::string& material) {
  s.walls.push_back(segment({-half_width, 0.0}, {half_width, 0.0}, material));
  s.walls.push_back(segment({-half_width, 0.0}, {-half_width, height}, material));
  s.walls.push_back(segment({half_width, 0.0}, {half_width, height}, material));
}

// `count` particles of `material`, radii uniform in [r_min, r_max], placed in a box.
inline FillSpec box_fill(const std::string& material, int count, double r_min, double r_max,
                         Vec2 box_min, Vec2 box_max) {
  FillSpec f;
  f.material = material;
  f.count = count;
  f.radius_min = r_min;
  f.radius_max = r_max;
  f.region = FillRegion::kBox;
  f.box_min = box_min;
  f.box_max = box_max;
  return f;
}

// Ore in the thesis drum with 60 balls (ramp 0.1 s): 40 ore spheres of 6 cm that break (E_min
// 0.01 J, S = 5 1/J, fragments down to 3.5 cm), a feed every 0.02 s and a grate of aperture
// 6 cm in the outer 0.5 m of the drum: breakage, feed and discharge all act within the first
// 0.3-0.4 s.
inline Scene grinding_drum_scene() {
  Scene s = thesis_drum_scene(60, 1.8, 16, 0.1);
  MaterialSpec ore = thesis_steel();
  ore.name = "ore";
  ore.density = 4800.0;
  s.materials.push_back(ore);
  FillSpec f = s.fills.front();
  f.material = "ore";
  f.count = 40;
  f.radius_min = f.radius_max = 0.06;
  s.fills.push_back(f);
  s.breakage = {.present = true,
                .material = "ore",
                .minimum_energy = 0.01,
                .strength = 5.0,
                .minimum_radius = 0.035};
  s.feed = {
      .present = true, .material = "ore", .period = 0.02, .radius_min = 0.04, .radius_max = 0.05};
  s.sieve = {.present = true,
             .material = "ore",
             .type = DischargeType::kGrate,
             .aperture = 0.06,
             .grate_width = 0.5};
  return s;
}

// A square lattice of side x side steel balls of `radius`, each touching its four neighbours
// (pitch 2 radius (1 - 1e-4)), centred on the origin, in rows (ids row by row), pushed at
// random: velocities up to 0.05 m/s, spins up to 0.5 rad/s.
inline void add_pushed_lattice(Scene& s, int side, double radius, unsigned seed) {
  const double pitch = 2.0 * radius * (1.0 - 1e-4);
  std::mt19937_64 draw(seed);
  std::uniform_real_distribution<double> push(-0.05, 0.05);
  for (int row = 0; row < side; ++row)
    for (int col = 0; col < side; ++col) {
      ParticleSpec b = ball("steel", radius,
                            {(col - 0.5 * (side - 1)) * pitch, (row - 0.5 * (side - 1)) * pitch});
      b.velocity = {push(draw), push(draw)};
      b.spin = 10.0 * push(draw);
      s.particles.push_back(b);
    }
}

// 200 balls of 2-20 mm radius (a 10:1 size range: four search levels) filling a 0.4 m drum of
// 8 sides that stirs them at 3 rad/s.
inline Scene ten_to_one_drum_scene() {
  Scene s = thesis_drum_scene(10, 3.0, 8, 0.0);
  s.drum.radius = 0.4;
  s.fills.front().count = 200;
  s.fills.front().region = FillRegion::kFull;
  s.fills.front().radius_min = 0.002;
  s.fills.front().radius_max = 0.02;
  return s;
}

}  // namespace dem2d::testing_support
