// SeriesRow: one row of series.csv, the run's global diagnostics at one time.
// Energies in J, torque in N m, power in W (docs/output.md). Energy balance:
// kinetic + rotational + potential + elastic + dissipated - drive_work - fed_energy +
// discharged_energy is constant (energy_balance below).
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
  // Drum scenes (core/mill/mill_analytics.hpp): the drive's torque and power through the shell and
  // through the lifters (drum_torque = shell_torque + lifter_torque), the power averaged over
  // the analysis window, the charge's shape and the regime over the window.
  double shell_torque = 0.0, lifter_torque = 0.0;  // N m
  double shell_power = 0.0, lifter_power = 0.0;    // W
  double drum_work = 0.0;                          // J, cumulative work of the drum's drive
  double power_avg = 0.0;                          // W, drum_work over the window / its length
  double toe_angle = 0.0, shoulder_angle = 0.0, surface_angle = 0.0, shell_arc = 0.0;  // deg
  double com_x = 0.0, com_y = 0.0;  // m from the drum centre
  double airborne_fraction = 0.0, corotating_fraction = 0.0;
  const char* regime = "-";
  double passes = 0.0;  // iterative integrator: mean passes per step since last row
  // Ore scenes ([breakage], [feed], [sieve]): counts and masses since the start.
  std::int64_t breakages = 0, fragments = 0, fed_count = 0, discharged_count = 0;
  double fed_mass = 0.0, discharged_mass = 0.0;  // kg
  double mill_mass = 0.0;                        // kg of every particle in the mill
  double ore_mass = 0.0;                         // kg of the ore (breakage/feed/sieve material)
  double fed_energy = 0.0;         // J the fed particles brought (kinetic + potential)
  double discharged_energy = 0.0;  // J the discharged ones took (kinetic + rotational + potential)
};

// The energy balance: constant up to the integrator's error.
inline double energy_balance(const SeriesRow& r) {
  return r.kinetic_energy + r.rotational_energy + r.potential_energy + r.elastic_energy +
         r.dissipated_energy - r.drive_work - r.fed_energy + r.discharged_energy;
}

}  // namespace dem2d
