// Hard cases for the time step and the blow-up detection (docs/models.md, "The time step,
// stability and guards"; exit status 3): fast steel impacts at the auto dt, a size ratio of 10,
// particles touching the walls at the start, the centrifuge scene, unsafe time steps refused or
// caught, and the largest time step each integrator survives in the thesis's waterfall scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "core/base/errors.hpp"
#include "core/run/simulation.hpp"
#include "core/shape/disc.hpp"
#include "support/runs.hpp"
#include "support/scenes.hpp"
#include "support/thesis.hpp"

namespace dem2d {
namespace {

using testing_support::head_on_pair;
using testing_support::thesis_steel;

Scene base_scene(IntegratorKind integrator = IntegratorKind::kVerlet) {
  Scene s;
  s.deck_path = "test_stability";
  s.materials.push_back(thesis_steel());
  s.run.integrator = integrator;
  s.run.dt_auto = true;
  return s;
}

void add_ball(Scene& s, Vec2 x, Vec2 v, double r, double spin = 0.0) {
  s.particles.push_back(testing_support::ball("steel", r, x, v, spin));
}

// The thesis drum (radius 2.5 m, regular polygon) with n balls of radius 0.1 m from the bottom.
Scene drum_scene(int n, double speed, int sides) {
  Scene s = testing_support::thesis_drum_scene(n, speed, sides);
  s.deck_path = "test_stability";
  return s;
}

bool all_finite(const ParticleStore& p) {
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    if (!std::isfinite(p.pos[k].x) || !std::isfinite(p.pos[k].y) || !std::isfinite(p.vel[k].x) ||
        !std::isfinite(p.vel[k].y))
      return false;
  return true;
}

std::string str(double x) {
  std::ostringstream o;
  o << x;
  return o.str();
}

const char* integrator_name(IntegratorKind k) {
  return k == IntegratorKind::kVerlet ? "verlet" : "iterative";
}

// ---------------------------------------------------------------------------------------------
// Two steel balls (r = 0.1 m) head-on at 20 m/s each, no gravity, dt = "auto".
struct HeadOn {
  double restitution = 0.0;  // obtained: separation speed / approach speed
  double max_overlap = 0.0;  // of the radius
  double dt = 0.0;
};
HeadOn head_on(double e, IntegratorKind integrator) {
  Scene s = base_scene(integrator);
  s.materials[0] = thesis_steel(e);
  s.run.gravity = {0.0, 0.0};
  s.particles = head_on_pair("steel", 0.1, 0.11, 20.0);
  Simulation sim(s);
  HeadOn out;
  out.dt = sim.dt();
  while (sim.time() < 2e-3) {
    sim.step();
    out.max_overlap = std::max(out.max_overlap, sim.last_totals().max_overlap);
  }
  EXPECT_EQ(sim.last_totals().contacts, 0);
  out.restitution = (sim.particles().vel[1].x - sim.particles().vel[0].x) / 40.0;
  EXPECT_EQ(sim.particles().vel[0].y, 0.0);
  return out;
}

// dt = "auto" resolves the shortest contact the scene can have with the intended number of
// steps: here a head-on pair of equal balls (reduced mass m/2, radius r/2, closing at twice the
// fastest ball's speed), not one ball against a wall at its own speed, which gave a contact
// time 32 % too long (15 steps instead of 20).
TEST(Stability, AutoDtResolvesAHeadOnPairWithTheIntendedSteps) {
  for (const double e : {1.0, 0.73}) {  // damping lengthens a contact: e = 0.3 takes 164 of 133
    Scene s = base_scene(IntegratorKind::kVerlet);
    s.materials[0] = thesis_steel(e);
    s.run.gravity = {0.0, 0.0};
    s.particles = head_on_pair("steel", 0.1, 0.11, 20.0);
    Simulation sim(s);
    int steps_in_contact = 0;
    while (sim.time() < 2e-3) {
      sim.step();
      steps_in_contact += sim.last_totals().contacts > 0 ? 1 : 0;
    }
    const double intended = steps_per_contact_for(sim.scales().restitution_min);
    std::cout << "[ auto dt ] head-on pair, e " << e << ": " << steps_in_contact
              << " steps in contact, intended " << intended << "\n";
    EXPECT_GE(steps_in_contact, intended - 1.0) << "e = " << e;
    EXPECT_LE(steps_in_contact, 1.2 * intended + 1.0) << "e = " << e << ": not needlessly small";
  }
}

// Thesis restitution (zeta_n = 0.1 -> e = 0.73) and e = 1: obtained within 1 %, and the largest
// overlap of the elastic impact equals Hertz's (docs/validation.md, "Hertz impact"):
// delta_max = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5) with v = 40 m/s.
TEST(Stability, HeadOnSteelAt20MetresPerSecondAtAutoDt) {
  const double m_eff = 0.5 * Disc::mass(0.1, 7800.0);
  const double e_star = 2.0e11 / (2.0 * (1.0 - 0.25 * 0.25));
  const double delta_max = std::pow(15.0 * m_eff * 1600.0 / (16.0 * e_star * std::sqrt(0.05)), 0.4);
  for (IntegratorKind integrator : {IntegratorKind::kVerlet, IntegratorKind::kIterative}) {
    for (double e : {0.73, 1.0}) {
      const HeadOn h = head_on(e, integrator);
      std::cout << "[ head-on ] " << integrator_name(integrator) << " dt " << h.dt << " s: e asked "
                << e << ", obtained " << h.restitution << "; max overlap " << h.max_overlap
                << " r (Hertz, elastic: " << delta_max / 0.1 << " r)\n";
      EXPECT_NEAR(h.restitution, e, 0.01 * e) << integrator_name(integrator);
      if (e == 1.0) {
        EXPECT_NEAR(h.max_overlap, delta_max / 0.1, 0.01 * delta_max / 0.1);
      }
    }
  }
}

// The restitution asked must be obtained within 1 % for 0.1 <= e <= 1 (docs/models.md, "Why
// N(e)"). At the auto dt (0.2 Rayleigh time = 2.14e-5 s) the 40 m/s steel contact lasts ~14 steps
// (t_c = 2.96e-4 s); Verlet's dashpot sees the half-step velocity (an O(dt) error) and the Hertz
// dashpot grows as delta^(1/4) from the first touch, so strongly damped impacts miss.
// Measured (Verlet / iterative, relative error): e = 0.1: -15 % / +3 %; 0.3: -3.9 % / +1.6 %;
// 0.5: -1.3 % / +0.9 %; 0.9: +0.01 % / +0.02 %. At dt = 2.5e-6 Verlet still gives -0.8 % at
// e = 0.1. See the report: either dt = "auto" must resolve damped contacts finer or the
// dashpots need a better velocity estimate.
TEST(Stability, HeadOnRestitutionRangeAtAutoDt) {
  for (IntegratorKind integrator : {IntegratorKind::kVerlet, IntegratorKind::kIterative}) {
    for (double e : {0.1, 0.3, 0.5, 0.9}) {
      const HeadOn h = head_on(e, integrator);
      std::cout << "[ head-on ] " << integrator_name(integrator) << " dt " << h.dt << " s: e asked "
                << e << ", obtained " << h.restitution << " (" << 100.0 * (h.restitution / e - 1.0)
                << " %)\n";
      EXPECT_NEAR(h.restitution, e, 0.01 * e) << integrator_name(integrator);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Size ratio 10 on a floor, dt = "auto" (set by the small balls): a 0.01 m ball resting on the
// apex of a 0.1 m ball; a 0.01 m ball thrown down at 5 m/s onto a resting 0.1 m ball, off-centre;
// a 0.1 m ball dropped 0.2 m onto a 0.01 m ball resting on the floor, off-centre.
TEST(Stability, SizeRatioTenRestingAndImpacting) {
  for (IntegratorKind integrator : {IntegratorKind::kVerlet, IntegratorKind::kIterative}) {
    Scene s = base_scene(integrator);
    s.walls.push_back(testing_support::segment({-5.0, 0.0}, {5.0, 0.0}, "steel"));
    add_ball(s, {0.0, 0.1}, {}, 0.1);
    add_ball(s, {0.0, 0.21}, {}, 0.01);
    add_ball(s, {1.0, 0.1}, {}, 0.1);
    add_ball(s, {1.03, 0.6}, {0.0, -5.0}, 0.01);
    add_ball(s, {2.0, 0.01}, {}, 0.01);
    add_ball(s, {2.05, 0.4}, {}, 0.1);
    Simulation sim(s);
    const double e0 = energy_balance(sim.diagnostics());
    double max_overlap = 0.0;
    bool hit_small = false, hit_big = false;
    while (sim.time() < 0.5) {
      sim.step();
      max_overlap = std::max(max_overlap, sim.last_totals().max_overlap);
      const ParticleStore& p = sim.particles();
      hit_small = hit_small || norm(p.pos[3] - p.pos[2]) < 0.11;
      hit_big = hit_big || norm(p.pos[5] - p.pos[4]) < 0.11;
    }
    const SeriesRow r = sim.diagnostics();
    const ParticleStore& p = sim.particles();
    const double residual = (energy_balance(r) - e0) / r.dissipated_energy;
    std::cout << "[ size ratio 10 ] " << integrator_name(integrator) << " dt " << sim.dt() << " s, "
              << sim.step_count() << " steps: max overlap " << max_overlap
              << " of the smaller radius, "
              << "balance residual " << residual << " of " << r.dissipated_energy
              << " J dissipated; resting "
              << "small ball moved " << norm(p.pos[1] - Vec2{0.0, 0.21}) << " m\n";
    EXPECT_TRUE(hit_small && hit_big);
    EXPECT_LT(max_overlap, 0.03);
    EXPECT_LT(std::abs(residual), 5e-3);
    EXPECT_LT(norm(p.pos[1] - Vec2{0.0, 0.21}), 1e-5) << "the small ball stays on the apex";
    EXPECT_LT(norm(p.vel[1]), 1e-6);
    for (std::size_t k = 0; k < p.n_owned(); ++k)
      EXPECT_GT(p.pos[k].y, 0.99 * p.radius[k]) << "above the floor";
  }
}

// ---------------------------------------------------------------------------------------------
// Particles placed exactly r from the shell (and exactly touching each other) are not ejected.
// Without gravity nothing may move; with gravity the balls on the lowest part of the shell may
// only start to roll (5/7 g sin 30 deg = 3.5 m/s^2 at most: 0.07 m/s after 20 ms).
TEST(Stability, ParticlesTouchingTheShellAtStartAreNotEjected) {
  for (int sides : {0, 16}) {
    for (bool gravity : {false, true}) {
      Scene s = drum_scene(0, 0.0, sides);
      s.fills.clear();
      s.drum.ramp_time = 0.0;
      if (!gravity) s.run.gravity = {0.0, 0.0};
      const double r = 0.1, pi = std::numbers::pi;
      if (sides == 0) {
        // Every 15 degrees around the circle without gravity, from -120 to -60 degrees with it;
        // at -90 degrees a radial column of two balls, touching the shell and each other.
        for (int k = 0; k < 24; ++k) {
          const double deg = 15.0 * k - 180.0;
          if (deg == -90.0 || (gravity && (deg < -120.0 || deg > -60.0))) continue;
          const double a = deg * pi / 180.0;
          add_ball(s, (2.5 - r) * Vec2{std::cos(a), std::sin(a)}, {}, r);
        }
        add_ball(s, {0.0, -(2.5 - r)}, {}, r);
        add_ball(s, {0.0, -(2.5 - 3.0 * r)}, {}, r);
      } else {
        // On every side's midpoint without gravity, on the two sides flanking the bottom vertex
        // (slope 11.25 degrees) with it.
        const double inner = 2.5 * std::cos(pi / sides);
        for (int k = 0; k < sides; ++k) {
          if (gravity && k != sides * 3 / 4 - 1 && k != sides * 3 / 4) continue;
          const double a = (k + 0.5) * 2.0 * pi / sides;
          add_ball(s, (inner - r) * Vec2{std::cos(a), std::sin(a)}, {}, r);
        }
      }
      Simulation sim(s);
      double v_max = 0.0;
      while (sim.time() < 0.02) {
        sim.step();
        for (std::size_t k = 0; k < sim.particles().n_owned(); ++k)
          v_max = std::max(v_max, norm(sim.particles().vel[k]));
      }
      std::cout << "[ touching ] " << (sides ? "16-gon" : "circle")
                << (gravity ? ", gravity" : ", no gravity") << ": " << sim.particles().n_owned()
                << " balls, largest speed in 20 ms " << v_max << " m/s\n";
      if (gravity)
        EXPECT_LT(v_max, 0.1);
      else
        EXPECT_LT(v_max, 1e-9);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// The thesis's centrifuge scene as in inputs/centrifuge.in (120 balls, 16-gon, 10 rad/s, ramp
// 0.5 s) for the full 10 s at dt = "auto" (about 2 s of wall time in Release). The 16-gon kicks the
// charge about as a "gas" for ~7.5 s before it centrifuges (see test_system.cpp), so the run
// meets impacts at up to the rim speed 25 m/s and then the pinned charge.
TEST(Stability, CentrifugeSceneRunsTenSeconds) {
  Scene s = drum_scene(120, 10.0, 16);
  Simulation sim(s);
  const auto [max_overlap, residual] = testing_support::run_drum(sim, 10.0);
  double worst_penetration = -1.0;  // of the radius, into the shell
  const ParticleStore& p = sim.particles();
  double l = 0.0, inertia = 0.0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    for (int e = 0; e < static_cast<int>(sim.walls().elements().size()); ++e)
      worst_penetration = std::max(
          worst_penetration, Disc::wall(sim.walls(), e, p.pos[k], p.radius[k]).delta / p.radius[k]);
    EXPECT_LT(norm(p.pos[k]), 2.5) << "inside the drum";
    l += p.mass[k] * cross(p.pos[k], p.vel[k]);
    inertia += p.mass[k] * norm2(p.pos[k]);
  }
  const SeriesRow r = sim.diagnostics();
  std::cout << "[ centrifuge ] 10 s at dt " << sim.dt() << " s: max overlap " << max_overlap
            << " r, balance residual " << residual << " of the drive work " << r.drive_work
            << " J, charge omega " << l / inertia << " rad/s at 10 s\n";
  EXPECT_LT(max_overlap, 0.05);
  EXPECT_LT(worst_penetration, 0.05);
  EXPECT_LT(std::abs(residual), 0.02);
  EXPECT_TRUE(all_finite(p));
}

// ---------------------------------------------------------------------------------------------
// A dt above half the smallest Rayleigh / Hertz time is refused with the safe dt in the message.
TEST(Stability, UnsafeDtIsRefusedNamingTheSafeDt) {
  Scene s = drum_scene(240, 1.8, 16);
  const Simulation reference(s);
  const TimeScales ts = reference.scales();
  EXPECT_NEAR(reference.dt(), ts.safe_dt, 1e-15);
  // safe dt = min(dt_safety T_R, t_c / N(e)); thesis steel (e = 0.73) needs N = 20 steps per
  // contact, and at 1.8 rad/s that bound (1.98e-5 s) is below 0.2 T_R (2.14e-5 s).
  EXPECT_DOUBLE_EQ(ts.steps_per_contact, 20.0);
  EXPECT_NEAR(ts.safe_dt, std::min(0.2 * ts.rayleigh, ts.hertz / 20.0), 1e-15);
  EXPECT_NEAR(ts.safe_dt, ts.hertz / 20.0, 1e-15) << "the restitution bound governs here";
  s.run.dt_auto = false;
  s.run.dt = 2.0 * ts.limit_dt;
  try {
    Simulation sim(s);
    ADD_FAILURE() << "dt = " << s.run.dt << " s was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    std::cout << "[ unsafe dt ] " << what;
    EXPECT_NE(what.find("safe dt is " + str(ts.safe_dt)), std::string::npos) << what;
    EXPECT_NE(what.find("allow_unsafe_dt"), std::string::npos) << what;
  }
  s.run.dt = 0.99 * ts.limit_dt;
  EXPECT_NO_THROW(Simulation{s});
}

// With allow_unsafe_dt a blow-up is caught by step(): the message names the particles and the
// safe dt, and the state left behind is finite.
TEST(Stability, BlowUpThrowsUnstableErrorNamingParticles) {
  Scene s = drum_scene(240, 1.8, 16);
  const double safe = Simulation(s).scales().safe_dt;
  s.run.dt_auto = false;
  s.run.dt = 4.8e-4;  // 22 x the safe dt
  s.run.allow_unsafe_dt = true;
  Simulation sim(s);
  bool threw = false;
  try {
    for (int k = 0; k < 10000; ++k) sim.step();
  } catch (const UnstableError& e) {
    threw = true;
    const std::string what = e.what();
    std::cout << "[ blow-up ] " << what << "\n";
    EXPECT_NE(what.find("safe dt is " + str(safe)), std::string::npos) << what;
    EXPECT_GT(e.step(), 0);
    std::smatch m;
    std::vector<std::int64_t> ids;
    for (std::string rest = what; std::regex_search(rest, m, std::regex("particle (\\d+)"));
         rest = m.suffix())
      ids.push_back(std::stoll(m[1]));
    ASSERT_FALSE(ids.empty()) << what;
    const ParticleStore& p = sim.particles();
    for (std::int64_t id : ids) EXPECT_LT(id, static_cast<std::int64_t>(p.n_owned()));
    // The pair named really overlaps by more than a quarter of a radius (ids are indices here).
    if (ids.size() == 2) {
      const std::size_t a = static_cast<std::size_t>(ids[0]), b = static_cast<std::size_t>(ids[1]);
      const double overlap = p.radius[a] + p.radius[b] - norm(p.pos[a] - p.pos[b]);
      EXPECT_GT(overlap, 0.25 * std::min(p.radius[a], p.radius[b]));
    }
  }
  EXPECT_TRUE(threw) << "dt = 4.8e-4 s should blow up";
  EXPECT_TRUE(all_finite(sim.particles()));
}

// Bodies never pass through each other with a clean exit: at a dt that lets two steel balls
// (r = 0.05 m, 2 x 100 m/s head-on) move a whole radius per step, both integrators stop at the
// first step, naming a particle that moves too far (kMaxStepMotion); the iterative scheme
// checks the state it returns, not only its last pass.
TEST(Stability, BodiesCannotPassThroughEachOtherUnseen) {
  for (const IntegratorKind integrator : {IntegratorKind::kVerlet, IntegratorKind::kIterative}) {
    Scene s = base_scene(integrator);
    s.run.gravity = {0.0, 0.0};
    add_ball(s, {-0.2, 0.0}, {0.0, 0.0}, 0.05);
    add_ball(s, {0.2, 0.0}, {0.0, 0.0}, 0.05);
    s.run.dt_auto = false;
    s.run.dt = 5.0e-4;  // 100 m/s x 5e-4 s = 0.05 m: one radius per step
    s.run.allow_unsafe_dt = true;
    Simulation sim(s);
    // Set after the start: such initial velocities are bad input (validate_start), so the
    // guard is met by a state the run reached.
    sim.particles().vel[0] = {100.0, 0.0};
    sim.particles().vel[1] = {-100.0, 0.0};
    std::string what;
    std::int64_t step = -1;
    try {
      for (int k = 0; k < 20; ++k) sim.step();
    } catch (const UnstableError& e) {
      what = e.what();
      step = e.step();
    }
    std::cout << "[ motion ] " << integrator_name(integrator) << ": " << what << "\n";
    EXPECT_EQ(step, 1) << integrator_name(integrator) << ": stopped before the balls could meet";
    EXPECT_NE(what.find("moves 1 times its radius in one step"), std::string::npos) << what;
    EXPECT_TRUE(what.find("particle 0") != std::string::npos ||
                what.find("particle 1") != std::string::npos)
        << what;
  }
}

// A run that creates energy does not end with exit 0: a Verlet head-on impact (steel, e = 0.73,
// 2 x 5 m/s) at 8 x the safe dt leaves at restitution 0.96; the balance check (every
// kEnergyCheckSteps steps and at the deck's last step) stops it naming the step. At the safe dt
// the same impact passes, with its balance error under the tolerance.
Scene head_on_impact() {
  Scene s = base_scene(IntegratorKind::kVerlet);
  s.materials[0] = thesis_steel(0.73);
  s.run.gravity = {0.0, 0.0};
  s.run.duration = 0.01;
  s.particles = head_on_pair("steel", 0.1, 0.11, 5.0);
  return s;
}

TEST(Stability, EnergyCreatedIsAnError) {
  Scene s = head_on_impact();
  const double safe = Simulation(s).dt();
  for (const double factor : {1.0, 8.0}) {
    s.run.dt_auto = false;
    s.run.dt = factor * safe;
    s.run.allow_unsafe_dt = true;
    Simulation sim(s);
    std::string what;
    try {
      while (sim.time() + 0.5 * sim.dt() < s.run.duration) sim.step();
    } catch (const UnstableError& e) {
      what = e.what();
    }
    std::cout << "[ energy guard ] " << factor << " x safe dt: "
              << (what.empty()
                      ? "no error, restitution " +
                            str((sim.particles().vel[1].x - sim.particles().vel[0].x) / 10.0)
                      : what)
              << "\n";
    if (factor == 1.0)
      EXPECT_TRUE(what.empty()) << what;
    else
      EXPECT_NE(what.find("energy was created"), std::string::npos) << "exit 3, not 0: " << what;
  }
}

// The same run with run.guards = "warn": the energy guard is recorded (kind, count, the message
// a stopping run would give) and the run goes on to its end.
TEST(Stability, GuardsCanWarnAndTheRunGoesOn) {
  Scene s = head_on_impact();
  const double safe = Simulation(s).dt();
  s.run.dt_auto = false;
  s.run.dt = 8.0 * safe;
  s.run.allow_unsafe_dt = true;
  s.run.guards_warn = true;
  Simulation sim(s);
  EXPECT_NO_THROW(sim.run_until(s.run.duration));
  EXPECT_GE(sim.time() + 0.5 * sim.dt(), s.run.duration);
  ASSERT_EQ(sim.guard_records().size(), 1U);
  EXPECT_EQ(sim.guard_records()[0].kind, "energy");
  EXPECT_EQ(sim.guard_records()[0].count, 1);
  EXPECT_NE(sim.guard_records()[0].first.find("energy was created"), std::string::npos);
}

// The iterative scheme's passes are a fixed-point iteration that contracts only while
// omega_contact dt < sqrt(6). A ball resting on a floor (omega_contact about 3600 rad/s) at
// dt = 1 ms: the passes cycle between the ball deeper in the floor and higher, their end positions
// a few percent of a radius apart, and the run stops (exit 3) naming the step and the particle,
// where before such steps were taken unconverged and counted. At the safe dt every step
// converges.
TEST(Stability, UnsettledIterativePassesAreAnError) {
  Scene s = base_scene(IntegratorKind::kIterative);
  s.materials[0] = thesis_steel(0.5);
  s.materials[0].sliding_friction = 10.0;  // the ball rocks on its tangential spring
  s.materials[0].rolling_friction = 0.0;
  testing_support::put_ball_on_steel_floor(s, 0.05, {0.01, 0.0});
  s.run.duration = 0.01;
  {
    Simulation sim(s);
    EXPECT_NO_THROW(sim.run_until(s.run.duration));
    EXPECT_EQ(sim.unconverged_steps(), 0) << "at the safe dt " << sim.dt() << " s";
  }
  s.run.dt_auto = false;
  s.run.dt = 1.0e-3;
  s.run.duration = 0.05;
  s.run.allow_unsafe_dt = true;
  Simulation sim(s);
  std::string what;
  std::int64_t step = -1;
  try {
    sim.run_until(s.run.duration);
  } catch (const UnstableError& e) {
    what = e.what();
    step = e.step();
  }
  std::cout << "[ passes ] " << what << "\n";
  EXPECT_GE(step, 1);
  EXPECT_LT(step, 50) << "stopped, not taken and counted to the end";
  EXPECT_NE(what.find("the iterative passes do not settle"), std::string::npos) << what;
  EXPECT_NE(what.find("end position of particle 0 by"), std::string::npos) << what;
}

// Non-finite blow-up: two balls given the same centre (their contact normal is 0/0) among
// others in a drum. Exit status 3 (docs/architecture.md, "Command line and exit status"): the
// message names the step, the time, the particle ids and the safe dt. The last finite state is
// restored.
TEST(Stability, NonFiniteBlowUpNamesParticlesAndRestoresTheLastFiniteState) {
  Scene s = drum_scene(20, 0.0, 0);
  add_ball(s, {0.5, 0.5}, {}, 0.1);
  add_ball(s, {0.5, 0.5}, {}, 0.1);  // ids 0 and 1 (explicit particles come first), same centre
  Simulation sim(s);
  const double safe = sim.scales().safe_dt;
  std::vector<Vec2> x0(sim.particles().pos.data(),
                       sim.particles().pos.data() + sim.particles().n_owned());
  try {
    for (int k = 0; k < 10; ++k) sim.step();
    ADD_FAILURE() << "coincident centres should give non-finite forces";
  } catch (const UnstableError& e) {
    const std::string what = e.what();
    std::cout << "[ blow-up ] " << what << "\n";
    EXPECT_NE(what.find("safe dt is " + str(safe)), std::string::npos) << what;
    EXPECT_NE(what.find("non-finite"), std::string::npos) << what;
    EXPECT_TRUE(std::regex_search(what, std::regex("particle [01]\\b")))
        << "names the particles: " << what;
  }
  EXPECT_TRUE(all_finite(sim.particles()));
  EXPECT_EQ(sim.time(), 0.0) << "restored to the last backup (the initial state)";
  for (std::size_t k = 0; k < x0.size(); ++k) EXPECT_EQ(sim.particles().pos[k], x0[k]);
}

// ---------------------------------------------------------------------------------------------
// Largest dt each integrator survives in the thesis's waterfall scene (240 balls, 16-gon,
// 1.8 rad/s). To meet real impacts the runs start from the cataracting state at t = 2 s
// (positions, velocities, spins and drum angle copied into a new scene with the drum at full
// speed; contact springs start unloaded), then run 0.3 s at dt = 1, 2, 4, 8, 16, 24, 32 x 1e-5 s.
// "Survives": no UnstableError. Also reported: the balance residual (fraction of the energy
// dissipated) and, for the iterative integrator, the fraction of steps that did not converge.
TEST(Stability, LargestDtSurvivedInTheWaterfallScene) {
  Scene s = drum_scene(240, 1.8, 16);
  Simulation prep(s);
  const double auto_dt = prep.dt();
  prep.run_until(2.0);
  Scene hot = s;
  hot.fills.clear();
  hot.drum.ramp_time = 0.0;
  hot.drum.angle = prep.walls().drum_angle();
  const ParticleStore& p = prep.particles();
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    add_ball(hot, p.pos[k], p.vel[k], p.radius[k], p.omega[k]);
  hot.run.dt_auto = false;
  hot.run.allow_unsafe_dt = true;

  const double dts[] = {1e-5, 2e-5, 4e-5, 8e-5, 16e-5, 24e-5, 32e-5};
  for (IntegratorKind integrator : {IntegratorKind::kVerlet, IntegratorKind::kIterative}) {
    double survived = 0.0, accurate = 0.0;
    bool failed = false, still_accurate = true;
    for (double dt : dts) {
      hot.run.dt = dt;
      hot.run.integrator = integrator;
      Simulation sim(hot);
      const double e0 = energy_balance(sim.diagnostics());
      try {
        sim.run_until(0.3);
      } catch (const UnstableError& e) {
        std::cout << "[ largest dt ] " << integrator_name(integrator) << " dt " << dt
                  << " s: UnstableError at t = " << e.time() << " s\n";
        EXPECT_TRUE(all_finite(sim.particles()));
        failed = true;
        break;
      }
      const SeriesRow r = sim.diagnostics();
      const double residual = (energy_balance(r) - e0) / r.dissipated_energy;
      const double unconverged = static_cast<double>(sim.unconverged_steps()) / sim.step_count();
      std::cout << "[ largest dt ] " << integrator_name(integrator) << " dt " << dt << " s ("
                << dt / auto_dt << " x auto): survived 0.3 s; balance residual " << residual
                << " of dissipated, passes/step " << r.passes << ", unconverged steps "
                << unconverged << "\n";
      survived = dt;
      if (still_accurate && std::abs(residual) < 0.02 && unconverged < 0.01)
        accurate = dt;
      else
        still_accurate = false;
    }
    std::cout << "[ largest dt ] " << integrator_name(integrator) << ": largest dt survived "
              << survived << " s (auto dt " << auto_dt
              << " s); largest with |residual| < 2 % and < 1 % unconverged steps " << accurate
              << " s\n";
    EXPECT_GE(survived, auto_dt) << integrator_name(integrator);
    EXPECT_GE(accurate, auto_dt) << integrator_name(integrator);
    EXPECT_TRUE(failed) << integrator_name(integrator)
                        << ": the blow-up must be caught by 3.2e-4 s";
  }
}

}  // namespace
}  // namespace dem2d
