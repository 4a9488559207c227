// work_precision: speed against error of the two integrators (docs/models.md, "Time integration").
//
// (a) Binary Hertz impact (docs/validation.md, "Hertz impact"): two thesis steel balls (r = 0.1 m,
//     E = 2e11 Pa, G = 8e10 Pa, rho = 7800) meet head-on at 2 x 5 m/s without gravity or
//     friction effects. With restitution 1 the contact time and the peak overlap are compared
//     with Hertz's closed form; with restitution 0.73 (the thesis steel) the restitution
//     obtained is compared with the one asked. dt runs from t_c/1000 up in factors of 2 until
//     two dt in a row fail: "unstable" (UnstableError / InputError; allow_unsafe_dt is on),
//     "no-separation" (the balls still touch after 20 t_c) or "diverged" (the rebound speed or
//     the peak overlap is off by more than 50 % at some touch phase: the contact is not
//     resolved, about 2 steps per contact).
//     Each dt is measured at 8 phases of the first touch within a step (the gap at the start
//     is u v dt, u = 1/16, 3/16, ..., 15/16); the error is the mean of |relative error| over
//     the phases, the worst phase is in the CSV. The impact is repeated (cycling the phases)
//     until the step loops have taken --min-time seconds; the wall time per contact is the
//     time of the step loops (from the reset just before touch until the balls separate)
//     divided by the repeats. The peak overlap is refined by a parabola through the largest
//     sample and its two neighbours (the raw largest sample is in the CSV too).
// (b) The waterfall scene (inputs/waterfall_polygon.in: 240 balls, 16-gon drum at 1.8 rad/s after a
//     0.5 s ramp), shortened to --duration seconds (default 2.0); time averages over
//     [--window-start (default 0.5), duration]: drum power = (drive work at the end - at the
//     start) / window (exact: the drive work is accumulated every step) and translational
//     kinetic energy (mean of samples every 1e-5 s of simulated time). For each integrator and
//     dt = 1, 2, 4, ... us until unstable, the errors are relative to a reference run with
//     velocity Verlet at dt_ref = 10 us / 16 = 0.625 us (the deck's dt / 16) and the same seed
//     (1). (dt_ref = 1 us / 16 would cost 32e6 steps, about 5 CPU minutes per run: too much for
//     a bench that should take about 10 minutes; as the errors turn out to be dominated by the
//     chaotic spread, not by dt, the finer reference would not change the conclusions.) The
//     waterfall is
//     chaotic: the same run at seed 2 (a different random placement) gives the noise floor,
//     and the same scene at dt = 10 us on seeds 1-4 gives a cheap estimate of the seed spread.
//     Wall and CPU time are the time spent in Simulation::step (not in the sampling).
//
// Output: tables on stdout, bench/results/work_precision_impact.csv and
// work_precision_waterfall.csv, and bench/results/work_precision.png drawn by
// post/plot_work_precision.py (run with /usr/bin/python3 through std::system; --no-plot skips).
//
//   work_precision [--quick] [--skip-impact] [--skip-waterfall] [--duration T]
//                  [--window-start T0] [--min-time S] [--no-plot] [--results DIR]
//
// --quick: impact with a shorter timing (0.02 s per point), waterfall 0.3 s with the window
// [0.15, 0.3] s, dt >= 4 us and the reference at 1 us (a smoke test; its numbers mean little).
//
// Times: every time is measured both as wall time and as the process's CPU time (the two agree
// on an idle machine; on a shared one the CPU time is the better measure); the repeats of an
// impact point run until the CPU time reaches --min-time (default 0.25 s).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/base/errors.hpp"
#include "core/run/simulation.hpp"
#include "core/shape/disc.hpp"
#include "core/shape/particles.hpp"
#include "io/deck.hpp"

namespace {

using dem2d::IntegratorKind;
using dem2d::Scene;
using dem2d::Simulation;
using dem2d::Vec2;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// CPU time of this (single-threaded) process: on a busy machine it is what the wall time would
// be on an idle one, so the tables give both.
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct IntegratorCase {
  std::string name;
  IntegratorKind kind;
  double tolerance;
};

const std::vector<IntegratorCase> kIntegrators = {
    {"verlet", IntegratorKind::kVerlet, 0.0},
    {"iterative-1e-6", IntegratorKind::kIterative, 1e-6},
    {"iterative-1e-3", IntegratorKind::kIterative, 1e-3},
};

void apply_integrator(Scene& s, const IntegratorCase& ic, double dt) {
  s.run.integrator = ic.kind;
  if (ic.kind == IntegratorKind::kIterative) s.run.tolerance = ic.tolerance;
  s.run.dt = dt;
  s.run.dt_auto = false;
  s.run.allow_unsafe_dt = true;
}

std::string first_line(const std::string& s) { return s.substr(0, s.find('\n')); }

struct Options {
  bool quick = false;
  bool impact = true;
  bool waterfall = true;
  bool plot = true;
  double duration = 2.0;
  double window_start = 0.5;
  double min_time = 0.25;  // s of step loops per impact point
  std::string results = DEM2D_SOURCE_DIR "/bench/results";
};

// ---------------------------------------------------------------------------------------------
// (a) Binary Hertz impact.

constexpr double kRadius = 0.1, kDensity = 7800.0, kYoung = 2.0e11, kShear = 8.0e10;
constexpr double kSpeed = 5.0;  // each ball; the relative speed is 2 kSpeed

struct Hertz {
  double delta_max, t_c, e_star, r_eff, m_eff;
};

// docs/validation.md, "Hertz impact": delta_max = (15 m* v^2 / (16 E* sqrt(R*)))^(2/5) and
// t_c = 2 int_0^1 (1 - x^(5/2))^(-1/2) dx delta_max / v = (4/5) B(2/5, 1/2) delta_max / v
//     = 2.94328 delta_max / v.
Hertz hertz_closed_form() {
  const double nu = kYoung / (2.0 * kShear) - 1.0;
  Hertz h;
  h.e_star = 1.0 / (2.0 * (1.0 - nu * nu) / kYoung);
  h.r_eff = 0.5 * kRadius;
  h.m_eff = 0.5 * dem2d::Disc::mass(kRadius, kDensity);
  const double v = 2.0 * kSpeed;
  h.delta_max = std::pow(15.0 * h.m_eff * v * v / (16.0 * h.e_star * std::sqrt(h.r_eff)), 0.4);
  const double beta = std::tgamma(0.4) * std::tgamma(0.5) / std::tgamma(0.9);
  h.t_c = 0.8 * beta * h.delta_max / v;
  return h;
}

Scene impact_scene(double restitution, const IntegratorCase& ic, double dt) {
  Scene s;
  s.title = "work_precision: binary Hertz impact";
  s.deck_path = "work_precision(impact)";
  s.run.gravity = {0.0, 0.0};
  s.run.duration = 1.0;
  apply_integrator(s, ic, dt);
  s.contact.model = dem2d::ContactModelKind::kHertzMindlin;
  s.contact.rolling = dem2d::RollingModelKind::kNone;
  dem2d::MaterialSpec steel;
  steel.name = "steel";
  steel.density = kDensity;
  steel.youngs_modulus = kYoung;
  steel.shear_modulus = kShear;
  steel.poisson_ratio = kYoung / (2.0 * kShear) - 1.0;
  steel.restitution = restitution;
  steel.sliding_friction = 0.1;
  steel.rolling_friction = 0.0;
  s.materials = {steel};
  dem2d::ParticleSpec a, b;
  a.material = b.material = "steel";
  a.radius = b.radius = kRadius;
  a.position = {-kRadius - 0.01, 0.0};
  b.position = {kRadius + 0.01, 0.0};
  a.velocity = {kSpeed, 0.0};  // so that the core's time scales see the impact speed
  b.velocity = {-kSpeed, 0.0};
  s.particles = {a, b};
  return s;
}

struct ImpactPoint {
  std::string integrator;
  double restitution_asked = 0.0;
  double dt = 0.0;
  std::string status = "ok";
  std::string message;
  double e = NAN, e_err = NAN, e_err_max = NAN;
  double tc = NAN, tc_err = NAN, tc_err_max = NAN;
  double dmax = NAN, dmax_err = NAN, dmax_err_max = NAN, dmax_raw_err = NAN;
  double wall_per_contact = NAN;
  double cpu_per_contact = NAN;
  double steps_per_contact = NAN;
  double passes_per_step = NAN;
  double unconverged_fraction = NAN;
  int repeats = 0;
};

struct OneImpact {
  bool separated = false;
  double e = NAN, tc = NAN, dmax = NAN, dmax_raw = NAN;
  std::int64_t steps = 0;
  double wall = 0.0;
  double cpu = 0.0;
};

// One impact: reset the two balls to touch within the first step (gap u v dt), step until they
// separate, and measure. Positions are found by id (the store may be reordered).
OneImpact impact_once(Simulation& sim, double u, std::int64_t max_steps) {
  dem2d::ParticleStore& p = sim.particles();
  const double v_rel = 2.0 * kSpeed;
  const double gap0 = u * v_rel * sim.dt();
  auto index_of = [&](std::int64_t id) {
    for (std::size_t k = 0; k < p.size(); ++k)
      if (p.id[k] == id) return k;
    return std::size_t{0};
  };
  std::size_t ia = index_of(0), ib = index_of(1);
  p.pos[ia] = {-kRadius - 0.5 * gap0, 0.0};
  p.pos[ib] = {kRadius + 0.5 * gap0, 0.0};
  p.vel[ia] = {kSpeed, 0.0};
  p.vel[ib] = {-kSpeed, 0.0};
  p.omega[ia] = p.omega[ib] = 0.0;
  p.theta[ia] = p.theta[ib] = 0.0;
  sim.rebuild();
  sim.refresh_forces();
  ia = index_of(0);
  ib = index_of(1);

  OneImpact out;
  std::vector<double> delta;  // -gap from the last step before touch to the first after
  delta.reserve(4096);
  double prev_gap = gap0, prev_t = sim.time(), t_start = NAN;
  bool touching = false;
  const auto t0 = Clock::now();
  const double c0 = cpu_seconds();
  for (std::int64_t k = 0; k < max_steps; ++k) {
    sim.step();
    const double gap = (p.pos[ib].x - p.pos[ia].x) - 2.0 * kRadius;
    const double t = sim.time();
    if (!touching && gap <= 0.0) {
      touching = true;
      t_start = prev_t + (t - prev_t) * prev_gap / (prev_gap - gap);
      delta.push_back(-prev_gap);
    }
    if (touching) delta.push_back(-gap);
    ++out.steps;
    if (touching && gap > 0.0) {
      const double t_end = prev_t + (t - prev_t) * (-prev_gap) / (gap - prev_gap);
      out.tc = t_end - t_start;
      out.separated = true;
      break;
    }
    prev_gap = gap;
    prev_t = t;
  }
  out.wall = seconds_since(t0);
  out.cpu = cpu_seconds() - c0;
  if (!out.separated) return out;
  out.e = (p.vel[ib].x - p.vel[ia].x) / v_rel;
  // Peak overlap: the largest sample, refined by a parabola through it and its neighbours.
  const auto it = std::max_element(delta.begin(), delta.end());
  const std::size_t k = static_cast<std::size_t>(it - delta.begin());
  out.dmax_raw = *it;
  out.dmax = *it;
  if (k > 0 && k + 1 < delta.size()) {
    const double y0 = delta[k - 1], y1 = delta[k], y2 = delta[k + 1];
    const double curv = y0 - 2.0 * y1 + y2;
    if (curv < 0.0) {
      const double s = 0.5 * (y0 - y2) / curv;  // vertex offset in steps, |s| <= 1/2
      out.dmax = y1 - 0.25 * (y0 - y2) * s;
    }
  }
  return out;
}

ImpactPoint run_impact_point(const IntegratorCase& ic, double restitution, double dt,
                             const Hertz& hz, double min_time) {
  ImpactPoint pt;
  pt.integrator = ic.name;
  pt.restitution_asked = restitution;
  pt.dt = dt;
  constexpr int kPhases = 8;
  const std::int64_t max_steps = static_cast<std::int64_t>(20.0 * hz.t_c / dt) + 20;
  try {
    Simulation sim(impact_scene(restitution, ic, dt));
    std::vector<double> e_err, tc_err, d_err, d_raw_err;
    double e_sum = 0.0, tc_sum = 0.0, d_sum = 0.0, wall = 0.0, cpu = 0.0;
    std::int64_t steps = 0;
    const std::int64_t passes0 = sim.passes_total(), unconv0 = sim.unconverged_steps(),
                       steps0 = sim.step_count();
    int rep = 0;
    for (; rep < 1000000; ++rep) {
      const double u = (rep % kPhases + 0.5) / kPhases;
      const OneImpact r = impact_once(sim, u, max_steps);
      if (!r.separated || !std::isfinite(r.e)) {
        pt.status = "no-separation";
        pt.message = "the balls did not separate within " + std::to_string(max_steps) + " steps";
        return pt;
      }
      wall += r.wall;
      cpu += r.cpu;
      steps += r.steps;
      if (rep < kPhases) {
        e_sum += r.e;
        tc_sum += r.tc;
        d_sum += r.dmax;
        e_err.push_back(std::abs(r.e / restitution - 1.0));
        tc_err.push_back(std::abs(r.tc / hz.t_c - 1.0));
        d_err.push_back(std::abs(r.dmax / hz.delta_max - 1.0));
        d_raw_err.push_back(std::abs(r.dmax_raw / hz.delta_max - 1.0));
      }
      if (rep + 1 >= kPhases && cpu >= min_time) break;
    }
    pt.repeats = rep + 1;
    // A step so coarse that the rebound speed changes by more than half at some touch phase
    // does not resolve the contact (about 2 steps per contact): in a many-body scene that is a
    // blow-up, so the point is marked and left out of the plot (its numbers stay in the CSV).
    constexpr double kDiverged = 0.5;
    auto mean = [](const std::vector<double>& v) {
      double s = 0.0;
      for (double x : v) s += x;
      return s / static_cast<double>(v.size());
    };
    auto max = [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); };
    pt.e = e_sum / kPhases;
    pt.e_err = mean(e_err);
    pt.e_err_max = max(e_err);
    // Hertz's closed form holds without damping; with damping only the restitution is checked.
    pt.tc = tc_sum / kPhases;
    pt.dmax = d_sum / kPhases;
    if (restitution == 1.0) {
      pt.tc_err = mean(tc_err);
      pt.tc_err_max = max(tc_err);
      pt.dmax_err = mean(d_err);
      pt.dmax_err_max = max(d_err);
      pt.dmax_raw_err = mean(d_raw_err);
    }
    if (pt.e_err_max > kDiverged || (restitution == 1.0 && pt.dmax_err_max > kDiverged)) {
      pt.status = "diverged";
      pt.message = "rebound speed or peak overlap off by more than 50 % at some touch phase";
    }
    pt.wall_per_contact = wall / pt.repeats;
    pt.cpu_per_contact = cpu / pt.repeats;
    pt.steps_per_contact = static_cast<double>(steps) / pt.repeats;
    const double n_steps = static_cast<double>(sim.step_count() - steps0);
    pt.passes_per_step = static_cast<double>(sim.passes_total() - passes0) / n_steps;
    pt.unconverged_fraction = static_cast<double>(sim.unconverged_steps() - unconv0) / n_steps;
  } catch (const dem2d::UnstableError& e) {
    pt.status = "unstable";
    pt.message = first_line(e.what());
  } catch (const dem2d::InputError& e) {
    pt.status = "unstable";
    pt.message = first_line(e.what());
  }
  return pt;
}

std::string fmt_num(double x, const char* f = "%.3e") {
  if (!std::isfinite(x)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

std::vector<ImpactPoint> impact_study(const Options& opt) {
  const Hertz hz = hertz_closed_form();
  std::printf("== (a) binary Hertz impact: steel r = %g m, v = 2 x %g m/s, no gravity\n", kRadius,
              kSpeed);
  std::printf("   Hertz: E* = %.4e Pa, R* = %g m, m* = %.4f kg, delta_max = %.6e m, t_c = %.6e s\n",
              hz.e_star, hz.r_eff, hz.m_eff, hz.delta_max, hz.t_c);
  {
    // The dt bounds the core uses for this scene, for reference.
    Simulation probe(impact_scene(1.0, kIntegrators[0], hz.t_c / 1000.0));
    std::printf(
        "   core time scales: Rayleigh %.3e s, Hertz %.3e s at %.3g m/s, safe dt %.3e s, limit "
        "%.3e s\n",
        probe.scales().rayleigh, probe.scales().hertz, probe.scales().impact_speed,
        probe.scales().safe_dt, probe.scales().limit_dt);
  }
  std::printf(
      "   errors: mean over 8 touch phases of |relative error|; cpu/c, wall/c: step-loop time per "
      "contact\n\n");
  std::printf("%-15s %5s %10s %8s %9s %10s %10s %10s %10s %10s %7s %7s %8s %s\n", "integrator", "e",
              "dt (s)", "dt/t_c", "steps/c", "e err", "t_c err", "dmax err", "cpu/c (s)",
              "wall/c (s)", "passes", "unconv", "repeats", "status");
  std::vector<ImpactPoint> points;
  for (const IntegratorCase& ic : kIntegrators) {
    for (double e : {1.0, 0.73}) {
      int unstable_in_a_row = 0;
      for (int k = 0; k <= 14 && unstable_in_a_row < 2; ++k) {
        const double dt = hz.t_c / 1000.0 * std::ldexp(1.0, k);
        ImpactPoint pt = run_impact_point(ic, e, dt, hz, opt.min_time);
        unstable_in_a_row = pt.status == "ok" ? 0 : unstable_in_a_row + 1;
        std::printf("%-15s %5.2f %10.3e %8.4f %9.1f %10s %10s %10s %10s %10s %7s %7s %8d %s%s%s\n",
                    ic.name.c_str(), e, dt, dt / hz.t_c, pt.steps_per_contact,
                    fmt_num(pt.e_err).c_str(), fmt_num(pt.tc_err).c_str(),
                    fmt_num(pt.dmax_err).c_str(), fmt_num(pt.cpu_per_contact).c_str(),
                    fmt_num(pt.wall_per_contact).c_str(),
                    fmt_num(pt.passes_per_step, "%.2f").c_str(),
                    fmt_num(pt.unconverged_fraction, "%.3f").c_str(), pt.repeats, pt.status.c_str(),
                    pt.message.empty() ? "" : ": ", pt.message.substr(0, 90).c_str());
        std::fflush(stdout);
        points.push_back(pt);
      }
    }
  }
  return points;
}

void write_impact_csv(const std::string& path, const std::vector<ImpactPoint>& pts) {
  const Hertz hz = hertz_closed_form();
  std::ofstream f(path);
  f << "integrator,restitution_asked,dt,dt_over_tc,status,restitution,restitution_err,restitution_"
       "err_max,"
       "contact_time,contact_time_err,contact_time_err_max,peak_overlap,peak_overlap_err,peak_"
       "overlap_err_max,"
       "peak_overlap_raw_err,steps_per_contact,passes_per_step,unconverged_fraction,wall_per_"
       "contact,cpu_per_contact,"
       "repeats,"
       "t_c_hertz,delta_max_hertz,message\n";
  for (const ImpactPoint& p : pts) {
    auto g = [](double x) { return fmt_num(x, "%.9g"); };
    std::string msg = p.message;
    std::replace(msg.begin(), msg.end(), '"', '\'');
    f << p.integrator << ',' << p.restitution_asked << ',' << g(p.dt) << ',' << g(p.dt / hz.t_c)
      << ',' << p.status << ',' << g(p.e) << ',' << g(p.e_err) << ',' << g(p.e_err_max) << ','
      << g(p.tc) << ',' << g(p.tc_err) << ',' << g(p.tc_err_max) << ',' << g(p.dmax) << ','
      << g(p.dmax_err) << ',' << g(p.dmax_err_max) << ',' << g(p.dmax_raw_err) << ','
      << g(p.steps_per_contact) << ',' << g(p.passes_per_step) << ',' << g(p.unconverged_fraction)
      << ',' << g(p.wall_per_contact) << ',' << g(p.cpu_per_contact) << ',' << p.repeats << ','
      << g(hz.t_c) << ',' << g(hz.delta_max) << ",\"" << msg << "\"\n";
  }
}

// ---------------------------------------------------------------------------------------------
// (b) The waterfall scene.

struct WaterfallRun {
  std::string role;  // "reference", "noise", "spread", "test"
  std::string integrator;
  double dt = 0.0;
  std::uint64_t seed = 1;
  std::string status = "ok";
  std::string message;
  double power = NAN, ke = NAN;
  double power_err = NAN, ke_err = NAN;
  double wall = NAN;  // s in Simulation::step over the whole run [0, duration]
  double cpu = NAN;   // CPU s of the same
  std::int64_t steps = 0;
  double passes_per_step = NAN;
  std::int64_t unconverged = 0;
  std::int64_t neighbor_builds = 0;
};

WaterfallRun run_waterfall(const Options& opt, const IntegratorCase& ic, double dt,
                           std::uint64_t seed, const std::string& role) {
  WaterfallRun out;
  out.role = role;
  out.integrator = ic.name;
  out.dt = dt;
  out.seed = seed;
  try {
    Scene s = dem2d::load_deck(DEM2D_SOURCE_DIR "/inputs/waterfall_polygon.in");
    s.run.duration = opt.duration;
    s.run.seed = seed;
    apply_integrator(s, ic, dt);
    Simulation sim(s);
    const double sample = 1.0e-5;  // s of simulated time between kinetic-energy samples
    const std::int64_t chunk = std::max<std::int64_t>(1, std::llround(sample / dt));
    double wall = 0.0, cpu = 0.0, ke_sum = 0.0, w_start = NAN, t_start = NAN;
    std::int64_t n_ke = 0;
    const std::int64_t passes0 = sim.passes_total();
    while (sim.time() + 0.5 * dt < opt.duration) {
      const auto t0 = Clock::now();
      const double c0 = cpu_seconds();
      for (std::int64_t k = 0; k < chunk && sim.time() + 0.5 * dt < opt.duration; ++k) sim.step();
      wall += seconds_since(t0);
      cpu += cpu_seconds() - c0;
      if (sim.time() + 0.5 * dt >= opt.window_start) {
        const dem2d::SeriesRow row = sim.diagnostics();
        if (std::isnan(w_start)) {
          w_start = row.drive_work;
          t_start = row.time;
          continue;  // the window starts here; its first sample is the next one
        }
        ke_sum += row.kinetic_energy;
        ++n_ke;
      }
    }
    const dem2d::SeriesRow end = sim.diagnostics();
    out.power = (end.drive_work - w_start) / (end.time - t_start);
    out.ke = ke_sum / static_cast<double>(n_ke);
    out.wall = wall;
    out.cpu = cpu;
    out.steps = sim.step_count();
    out.passes_per_step =
        static_cast<double>(sim.passes_total() - passes0) / static_cast<double>(out.steps);
    out.unconverged = sim.unconverged_steps();
    out.neighbor_builds = sim.neighbor_builds();
  } catch (const dem2d::UnstableError& e) {
    out.status = "unstable";
    out.message = first_line(e.what());
  } catch (const dem2d::InputError& e) {
    out.status = "unstable";
    out.message = first_line(e.what());
  }
  return out;
}

void print_waterfall_row(const WaterfallRun& r) {
  std::printf("%-10s %-15s %10.3e %5llu %12s %12s %10s %10s %9s %9s %9s %8s %6lld %s%s%s\n",
              r.role.c_str(), r.integrator.c_str(), r.dt, static_cast<unsigned long long>(r.seed),
              fmt_num(r.power, "%.2f").c_str(), fmt_num(r.ke, "%.2f").c_str(),
              fmt_num(r.power_err, "%+.2e").c_str(), fmt_num(r.ke_err, "%+.2e").c_str(),
              fmt_num(r.cpu, "%.2f").c_str(), fmt_num(r.wall, "%.2f").c_str(),
              fmt_num(r.passes_per_step, "%.2f").c_str(), std::to_string(r.steps).c_str(),
              static_cast<long long>(r.unconverged), r.status.c_str(),
              r.message.empty() ? "" : ": ", r.message.substr(0, 90).c_str());
  std::fflush(stdout);
}

std::vector<WaterfallRun> waterfall_study(const Options& opt) {
  const double dt_min = opt.quick ? 4.0e-6 : 1.0e-6;
  const double dt_ref = opt.quick ? 1.0e-6 : 1.0e-5 / 16.0;
  std::printf(
      "\n== (b) waterfall scene (inputs/waterfall_polygon.in) shortened to %.2f s; averages over "
      "[%.2f, "
      "%.2f] s\n",
      opt.duration, opt.window_start, opt.duration);
  std::printf(
      "   reference: verlet at dt_ref = %.4g s, seed 1; errors relative to it; cpu, wall: time in "
      "step()\n\n",
      dt_ref);
  std::printf("%-10s %-15s %10s %5s %12s %12s %10s %10s %9s %9s %9s %8s %6s %s\n", "role",
              "integrator", "dt (s)", "seed", "power (W)", "KE (J)", "power err", "KE err",
              "cpu (s)", "wall (s)", "passes", "steps", "unconv", "status");
  std::vector<WaterfallRun> runs;
  const auto t_all = Clock::now();
  WaterfallRun ref = run_waterfall(opt, kIntegrators[0], dt_ref, 1, "reference");
  print_waterfall_row(ref);
  runs.push_back(ref);
  if (ref.status != "ok") {
    std::printf("the reference run failed; no errors can be computed\n");
    return runs;
  }
  WaterfallRun noise = run_waterfall(opt, kIntegrators[0], dt_ref, 2, "noise");
  noise.power_err = noise.power / ref.power - 1.0;
  noise.ke_err = noise.ke / ref.ke - 1.0;
  print_waterfall_row(noise);
  runs.push_back(noise);
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    WaterfallRun r = run_waterfall(opt, kIntegrators[0], 1.0e-5, seed, "spread");
    if (r.status == "ok") {
      r.power_err = r.power / ref.power - 1.0;
      r.ke_err = r.ke / ref.ke - 1.0;
    }
    print_waterfall_row(r);
    runs.push_back(r);
  }
  for (const IntegratorCase& ic : kIntegrators) {
    for (int k = 0; k <= 10; ++k) {
      const double dt = dt_min * std::ldexp(1.0, k);
      WaterfallRun r = run_waterfall(opt, ic, dt, 1, "test");
      if (r.status == "ok") {
        r.power_err = r.power / ref.power - 1.0;
        r.ke_err = r.ke / ref.ke - 1.0;
      }
      print_waterfall_row(r);
      runs.push_back(r);
      if (r.status != "ok") break;
    }
  }
  std::printf("   (b) took %.1f s of wall time\n", seconds_since(t_all));
  return runs;
}

void write_waterfall_csv(const std::string& path, const Options& opt,
                         const std::vector<WaterfallRun>& runs) {
  std::ofstream f(path);
  f << "role,integrator,dt,seed,status,duration,window_start,power,power_err,kinetic_energy,"
       "kinetic_energy_err,"
       "wall,cpu,steps,passes_per_step,unconverged_steps,neighbor_builds,message\n";
  for (const WaterfallRun& r : runs) {
    auto g = [](double x) { return fmt_num(x, "%.9g"); };
    std::string msg = r.message;
    std::replace(msg.begin(), msg.end(), '"', '\'');
    f << r.role << ',' << r.integrator << ',' << g(r.dt) << ',' << r.seed << ',' << r.status << ','
      << opt.duration << ',' << opt.window_start << ',' << g(r.power) << ',' << g(r.power_err)
      << ',' << g(r.ke) << ',' << g(r.ke_err) << ',' << g(r.wall) << ',' << g(r.cpu) << ','
      << r.steps << ',' << g(r.passes_per_step) << ',' << r.unconverged << ',' << r.neighbor_builds
      << ",\"" << msg << "\"\n";
  }
}

// ---------------------------------------------------------------------------------------------
// Summaries: the best default.

// Largest dt / t_c per integrator at which every impact error is <= 1 % (restitution at
// e = 0.73; contact time and peak overlap at e = 1); 0 if none.
struct ImpactBest {
  double ratio = 0.0;  // dt / t_c
  double cpu = NAN;    // CPU s per contact there
};

std::vector<ImpactBest> summarize_impact(const std::vector<ImpactPoint>& pts) {
  std::printf(
      "\n== impact: largest dt per integrator with every error <= 1 %% (restitution at e = 0.73; "
      "contact time and peak overlap at e = 1)\n");
  const Hertz hz = hertz_closed_form();
  std::vector<ImpactBest> out;
  for (const IntegratorCase& ic : kIntegrators) {
    double best = 0.0, cpu = NAN;
    for (const ImpactPoint& a : pts) {
      if (a.integrator != ic.name || a.restitution_asked != 1.0 || a.status != "ok") continue;
      if (!(a.tc_err <= 0.01 && a.dmax_err <= 0.01)) continue;
      for (const ImpactPoint& b : pts)
        if (b.integrator == ic.name && b.restitution_asked != 1.0 && b.dt == a.dt &&
            b.status == "ok" && b.e_err <= 0.01 && a.dt > best) {
          best = a.dt;
          cpu = 0.5 * (a.cpu_per_contact + b.cpu_per_contact);
        }
    }
    out.push_back({best / hz.t_c, cpu});
    if (best > 0.0)
      std::printf("   %-15s dt = %.3e s = t_c / %.1f, %.3e CPU s per contact\n", ic.name.c_str(),
                  best, hz.t_c / best, cpu);
    else
      std::printf("   %-15s none\n", ic.name.c_str());
  }
  return out;
}

struct Spread {
  double noise_p = NAN, noise_k = NAN;  // |seed 2 - seed 1| / seed 1 at dt_ref
  double sd_p = NAN, sd_k = NAN;        // relative standard deviation over the seeds at 1e-5 s
};

Spread summarize_waterfall(const std::vector<WaterfallRun>& runs) {
  Spread sp;
  std::vector<double> p, k;
  for (const WaterfallRun& r : runs) {
    if (r.role == "noise" && r.status == "ok") {
      sp.noise_p = std::abs(r.power_err);
      sp.noise_k = std::abs(r.ke_err);
    }
    if (r.role == "spread" && r.status == "ok") {
      p.push_back(r.power);
      k.push_back(r.ke);
    }
  }
  std::printf(
      "\n== waterfall: noise floor (reference at seed 2 vs seed 1): power %.2f %%, kinetic energy "
      "%.2f %%\n",
      100.0 * sp.noise_p, 100.0 * sp.noise_k);
  auto rel_sd = [](const std::vector<double>& v) {
    double m = 0.0, s2 = 0.0;
    for (double x : v) m += x;
    m /= static_cast<double>(v.size());
    for (double x : v) s2 += (x - m) * (x - m);
    return std::sqrt(s2 / static_cast<double>(v.size() - 1)) / m;
  };
  if (p.size() >= 2) {
    sp.sd_p = rel_sd(p);
    sp.sd_k = rel_sd(k);
    std::printf(
        "   seed spread at dt = 1e-5 s over %zu seeds: power sd %.2f %%, kinetic energy sd %.2f %% "
        "of the mean\n"
        "   (the difference of two runs has sd sqrt(2) times that: %.2f %% and %.2f %%)\n",
        p.size(), 100.0 * sp.sd_p, 100.0 * sp.sd_k, 100.0 * std::sqrt(2.0) * sp.sd_p,
        100.0 * std::sqrt(2.0) * sp.sd_k);
  }
  std::printf(
      "   best default by the rule asked (largest dt with both errors within 1 %% of the "
      "reference): ");
  const WaterfallRun* best = nullptr;
  for (const WaterfallRun& r : runs)
    if (r.role == "test" && r.status == "ok" && std::abs(r.power_err) <= 0.01 &&
        std::abs(r.ke_err) <= 0.01 &&
        (!best || r.dt > best->dt || (r.dt == best->dt && r.cpu < best->cpu)))
      best = &r;
  if (best)
    std::printf("%s, dt = %.3e s\n", best->integrator.c_str(), best->dt);
  else
    std::printf("none\n");
  const bool noisy = sp.noise_p > 0.01 || sp.noise_k > 0.01 || sp.sd_p > 0.01 || sp.sd_k > 0.01;
  if (noisy)
    std::printf(
        "   but the chaotic run-to-run spread exceeds 1 %%, so that rule picks by chance. Within "
        "two standard\n"
        "   deviations of a difference (2 sqrt(2) sd):\n");
  for (const IntegratorCase& ic : kIntegrators) {
    const WaterfallRun* last_ok = nullptr;
    const WaterfallRun* last_within = nullptr;
    bool all_within = true;
    for (const WaterfallRun& r : runs) {
      if (r.role != "test" || r.integrator != ic.name || r.status != "ok") continue;
      last_ok = &r;
      const bool within = std::abs(r.power_err) <= 2.0 * std::sqrt(2.0) * sp.sd_p &&
                          std::abs(r.ke_err) <= 2.0 * std::sqrt(2.0) * sp.sd_k;
      if (within && all_within) last_within = &r;
      all_within = all_within && within;
    }
    if (last_ok)
      std::printf(
          "   %-15s largest stable dt %.3e s; every dt up to %.3e s agrees with the reference "
          "within the spread\n",
          ic.name.c_str(), last_ok->dt, last_within ? last_within->dt : 0.0);
  }
  return sp;
}

// The verdict: the waterfall's time averages only show where a dt goes unstable; the accuracy
// limit comes from the impact test, applied to the scene's fastest expected impact.
void recommend(const std::vector<ImpactBest>& impact, const std::vector<WaterfallRun>& runs) {
  Scene s = dem2d::load_deck(DEM2D_SOURCE_DIR "/inputs/waterfall_polygon.in");
  const Simulation probe(s);
  const double tc = probe.scales().hertz;
  std::printf("\n== recommended default\n");
  std::printf(
      "   waterfall: Hertz contact time at its largest expected impact speed (%.3g m/s, ball on "
      "shell) = %.3e s\n",
      probe.scales().impact_speed, tc);
  std::size_t pick = impact.size();
  for (std::size_t k = 0; k < kIntegrators.size() && k < impact.size(); ++k) {
    if (impact[k].ratio <= 0.0) continue;
    if (pick == impact.size() || impact[k].cpu < impact[pick].cpu) pick = k;
    double stable = 0.0, cpu_at = NAN;
    const double dt_acc = impact[k].ratio * tc;
    for (const WaterfallRun& r : runs)
      if (r.role == "test" && r.integrator == kIntegrators[k].name && r.status == "ok") {
        stable = std::max(stable, r.dt);
        if (r.dt <= dt_acc * (1.0 + 1e-9))
          cpu_at = r.cpu;  // the run at the largest tested dt <= dt_acc
      }
    std::printf(
        "   %-15s 1 %% impact accuracy needs dt <= t_c / %.1f = %.2e s (waterfall stable up to "
        "%.2e s); "
        "the waterfall at the largest tested dt below that took %.2f CPU s\n",
        kIntegrators[k].name.c_str(), 1.0 / impact[k].ratio, dt_acc, stable, cpu_at);
  }
  if (pick == impact.size()) return;
  std::printf(
      "   => %s with dt = t_c / %.0f of the fastest impact (the cheapest per contact at 1 %% "
      "impact accuracy:\n"
      "      %.2e CPU s). For the waterfall that is %.1e s; its deck's dt of %.0e s is t_c / "
      "%.0f.\n",
      kIntegrators[pick].name.c_str(), 1.0 / impact[pick].ratio, impact[pick].cpu,
      impact[pick].ratio * tc, s.run.dt, tc / s.run.dt);
}

Options parse(int argc, char** argv) {
  Options o;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    auto value = [&]() -> std::string {
      if (k + 1 >= argc) {
        std::fprintf(stderr, "work_precision: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++k];
    };
    if (a == "--quick") {
      o.quick = true;
      o.duration = 0.3;
      o.window_start = 0.15;
      o.min_time = 0.02;
    } else if (a == "--skip-impact") {
      o.impact = false;
    } else if (a == "--skip-waterfall") {
      o.waterfall = false;
    } else if (a == "--no-plot") {
      o.plot = false;
    } else if (a == "--duration") {
      o.duration = std::stod(value());
    } else if (a == "--window-start") {
      o.window_start = std::stod(value());
    } else if (a == "--min-time") {
      o.min_time = std::stod(value());
    } else if (a == "--results") {
      o.results = value();
    } else {
      std::fprintf(
          stderr,
          "usage: work_precision [--quick] [--skip-impact] [--skip-waterfall] [--duration T] "
          "[--window-start T0] [--min-time S] [--no-plot] [--results DIR]\n");
      std::exit(a == "--help" || a == "-h" ? 0 : 2);
    }
  }
  if (!(o.window_start < o.duration)) {
    std::fprintf(stderr, "work_precision: --window-start must be below --duration\n");
    std::exit(2);
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  const auto t0 = Clock::now();
  std::filesystem::create_directories(opt.results);
  const std::string impact_csv = opt.results + "/work_precision_impact.csv";
  const std::string waterfall_csv = opt.results + "/work_precision_waterfall.csv";
  std::vector<ImpactPoint> impact;
  std::vector<WaterfallRun> waterfall;
  if (opt.impact) {
    const auto ta = Clock::now();
    impact = impact_study(opt);
    write_impact_csv(impact_csv, impact);
    std::printf("   (a) took %.1f s of wall time; wrote %s\n", seconds_since(ta),
                impact_csv.c_str());
  }
  if (opt.waterfall) {
    waterfall = waterfall_study(opt);
    write_waterfall_csv(waterfall_csv, opt, waterfall);
    std::printf("   wrote %s\n", waterfall_csv.c_str());
  }
  std::vector<ImpactBest> impact_best;
  if (opt.impact) impact_best = summarize_impact(impact);
  if (opt.waterfall) summarize_waterfall(waterfall);
  if (opt.impact && opt.waterfall) recommend(impact_best, waterfall);
  if (opt.plot) {
    const std::string png = opt.results + "/work_precision.png";
    const std::string cmd = "/usr/bin/python3 " DEM2D_SOURCE_DIR
                            "/post/plot_work_precision.py --impact '" +
                            impact_csv + "' --waterfall '" + waterfall_csv + "' -o '" + png + "'";
    std::printf("\n$ %s\n", cmd.c_str());
    std::fflush(stdout);
    if (std::system(cmd.c_str()) != 0) std::printf("work_precision: the plot script failed\n");
  }
  std::printf("work_precision: total %.1f s of wall time\n", seconds_since(t0));
  return 0;
}
