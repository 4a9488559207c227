// SeriesRow: one row of series.csv, the run's global diagnostics at one time.
// Energies in J, torque in N m, power in W (docs/output.md). Energy balance:
// kinetic + rotational + potential + elastic + dissipated - drive_work is constant.
#pragma once

#include <cstdint>

namespace dem2d {

struct SeriesRow {
  double time = 0.0;
  std::int64_t step = 0;
  std::int64_t particles = 0;
  std::int64_t contacts = 0;       // particle-particle plus particle-wall contacts
  double kinetic_energy = 0.0;     // sum 1/2 m v^2
  double rotational_energy = 0.0;  // sum 1/2 I w^2
  double potential_energy = 0.0;   // sum -m g . x (zero at the origin)
  double elastic_energy = 0.0;     // stored in contact springs (normal, tangential, rolling)
  double dissipated_energy = 0.0;  // cumulative: damping, sliding, rolling plasticity
  double drum_torque = 0.0;        // torque the drive applies to keep the drum's speed
  double drum_power = 0.0;         // drum_torque * drum speed
  double drive_work = 0.0;         // cumulative work done by the drive (and moving walls)
  double passes = 0.0;             // iterative integrator: mean passes per step since last row
};

}  // namespace dem2d
