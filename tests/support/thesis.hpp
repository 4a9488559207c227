// Shared test fixtures: the thesis's steel (seed 000, Table 1) and its drum.
#pragma once

#include "core/scene.hpp"

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

}  // namespace dem2d::testing_support
