// The energy ledger: where the energy of a run went, this rank's share of each sum since the
// start (J). The balance kinetic + rotational + potential + elastic + dissipated - drive work
// - fed + discharged stays constant up to the integrator's error (docs/models.md, "Energy
// bookkeeping"); Simulation keeps one ledger, checkpoints save it, the series reports its sums.
#pragma once

#include <cstddef>

#include "core/base/vec2.hpp"
#include "core/contact/contact_engine.hpp"
#include "core/shape/particles.hpp"

namespace dem2d {

struct EnergyLedger {
  double dissipated = 0.0;  // by the contacts, and what population changes released
  double drive_work = 0.0;  // work of every moving wall on the particles
  double drum_work = 0.0;   // of the drum's drive alone
  double fed = 0.0;         // kinetic, rotational and potential energy the feed brought in
  double discharged = 0.0;  // the same, taken out by the sieve

  // One step's contact totals: the losses the laws booked with `late_loss` (the integrator's
  // completion of their work), the walls' power over dt, the drum's at its speed `drum_omega`.
  void book(const EvaluationTotals& t, double dt, double late_loss, double drum_omega) {
    dissipated += t.dissipated + late_loss;
    drive_work += t.drive_power * dt;
    drum_work += t.drum_torque * drum_omega * dt;
  }
};

// Kinetic, rotational and potential energy of particle k (J), with its shape's inertia.
double mechanical_energy(const ParticleStore& p, std::size_t k, Vec2 gravity);

}  // namespace dem2d
