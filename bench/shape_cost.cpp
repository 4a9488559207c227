// shape_cost: what a superellipse costs against a disc, per particle-step in a drum, and what the
// pair solve's tolerance buys.
//
// Drum: the thesis drum (radius 2.5 m, 1 rad/s after a 0.1 s ramp, steel of the thesis's Table 1,
// dt = 1e-5 s) holding 400 bodies of bounding radius 0.1 m on a square grid 0.21 m apart, each at
// a random angle and velocity (seeded; the recipe of tests/support/thesis.hpp, shaped_drum_scene,
// with the semi-axes scaled so that every shape's bounding radius is 0.1 m): discs, ellipses of
// aspect 0.6, rounded squares n = 8 and n = 4 of aspect 0.5. Each scene is first run for --warm
// seconds, then stepped in blocks of --steps steps that take the scenes in turn, the order
// rotated each round, each block timed by the thread's CPU clock: a slow minute of the host falls
// on neighbouring blocks of every scene alike. The ratio to discs is taken block by block within
// a round.
//
// Tolerance: random overlapping poses of two bodies of each shape (overlaps 0.1-5 % of the
// bounding radius), solved by contact_depth at tol 1e-6, 1e-8, 1e-10 and 1e-12 from a cold start
// and warm-started from the normal of the same pose 1e-4 rad and 1e-4 m away (a contact one step
// on), against a cold solve at tol 1e-14: the normal's angle error and ns per pair solve.
//
//   shape_cost [--rounds R] [--steps S] [--warm T] [--poses P] [--only TEXT] [--results DIR]
//              [--csv NAME]
//
// --only: the shapes whose name holds TEXT ("ellipses", "n=8", ...), with the discs. Defaults: 10
// rounds, S = 400, T = 0.2 s, P = 2000. Writes DIR/NAME (default bench/results/shape_cost.csv:
// scene, round, ns per particle-step, ratio to discs, pair solves and evaluations per solve) and
// DIR/shape_cost_tolerance.csv (shape, tol, start, errors, ns).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "blocks.hpp"
#include "core/run/simulation.hpp"
#include "core/shape/superellipse.hpp"
#include "core/shape/superellipse_shape.hpp"

namespace {

struct Options {
  int rounds = 10;
  int steps = 400;
  double warm = 0.2;
  int poses = 2000;
  std::string results = DEM2D_SOURCE_DIR "/bench/results";
  std::string csv = "shape_cost.csv";
  std::string only;  // a scene's name holds this (and discs always run)
};

int usage() {
  std::fprintf(stderr,
               "usage: shape_cost [--rounds R] [--steps S] [--warm T] [--poses P] [--only TEXT]\n"
               "                  [--results DIR] [--csv NAME]\n");
  return 2;
}

struct Form {
  const char* name;
  bool shaped;
  double aspect;  // b / a
  double n;
};

constexpr Form kForms[] = {{"discs", false, 1.0, 2.0},
                           {"ellipses 0.6", true, 0.6, 2.0},
                           {"squares n=8", true, 1.0, 8.0},
                           {"n=4 aspect 0.5", true, 0.5, 4.0}};

// The semi-axes (a, aspect a) of exponent n whose bounding radius is r.
dem2d::SuperEllipse scaled_form(const Form& f, double r) {
  const dem2d::SuperEllipse unit{1.0, f.aspect, f.n};
  const double k = r / dem2d::bounding_radius(unit);
  return {k, k * f.aspect, f.n};
}

dem2d::Scene drum_scene(const Form& f, int count, std::uint32_t seed = 7) {
  dem2d::Scene s;
  s.title = f.name;
  s.deck_path = "bench";
  dem2d::MaterialSpec m;
  m.name = "steel";
  m.density = 7800.0;
  m.youngs_modulus = 2.0e11;
  m.poisson_ratio = 0.25;
  m.shear_modulus = 8.0e10;
  m.restitution = 0.73;
  m.sliding_friction = 0.1;
  m.rolling_friction = 0.05;
  s.materials.push_back(m);
  s.run.dt_auto = false;
  s.run.dt = 1e-5;
  s.run.duration = 100.0;
  s.drum.present = true;
  s.drum.radius = 2.5;
  s.drum.speed = 1.0;
  s.drum.ramp_time = 0.1;
  s.drum.material = "steel";
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> turn(0.0, 3.14159265358979);
  const double r = 0.1, spacing = 0.21, inner = 2.5 - 1.05 * r;
  const dem2d::SuperEllipse se = scaled_form(f, r);
  for (double y = -inner; y < inner && static_cast<int>(s.particles.size()) < count; y += spacing)
    for (double x = -inner; x < inner && static_cast<int>(s.particles.size()) < count;
         x += spacing) {
      if (x * x + y * y > inner * inner) continue;
      const double vx = 2.0 * turn(rng) / 3.14159265358979 - 1.0;
      const double vy = 2.0 * turn(rng) / 3.14159265358979 - 1.0;
      dem2d::ParticleSpec p;
      p.material = "steel";
      p.radius = r;
      p.position = {x, y};
      p.velocity = {vx, vy};
      if (f.shaped) {
        p.semi_a = se.a;
        p.semi_b = se.b;
        p.exponent = se.n;
        p.angle = turn(rng);
      }
      s.particles.push_back(p);
    }
  return s;
}

struct Drum {
  const Form* form = nullptr;
  std::unique_ptr<dem2d::Simulation> sim;
  std::size_t bodies = 0;
  std::vector<double> ns;  // per round: thread CPU ns per particle-step
  std::int64_t pair_solves = 0, evaluations = 0, unconverged = 0, wall_solves = 0, cold = 0;
  std::int64_t steps = 0;
};

// ---- Tolerance against error -------------------------------------------------------------------

struct Pose {
  dem2d::SuperPose i, j;
};

// Random poses of two bodies of form s overlapping by 0.1-5 % of the bounding radius along a
// random direction (j moved back along it from where the support points meet).
std::vector<Pose> overlapping_poses(const dem2d::SuperEllipse& s, int count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  std::uniform_real_distribution<double> depth(0.001, 0.05);
  const double R = dem2d::bounding_radius(s);
  std::vector<Pose> out;
  for (int k = 0; k < count; ++k) {
    Pose p;
    p.i.theta = angle(rng);
    p.j.theta = angle(rng);
    const double phi = angle(rng);
    const dem2d::Vec2 u{std::cos(phi), std::sin(phi)};
    const double reach = dot(dem2d::support_lab(s, {}, p.i.theta, u), u) +
                         dot(dem2d::support_lab(s, {}, p.j.theta, -u), -u);
    p.j.centre = (reach - depth(rng) * R) * u;
    out.push_back(p);
  }
  return out;
}

double angle_between(dem2d::Vec2 a, dem2d::Vec2 b) {
  return std::abs(std::atan2(cross(a, b), dot(a, b)));
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  try {
    for (int k = 1; k < argc; ++k) {
      const std::string a = argv[k];
      const auto value = [&]() -> std::string {
        if (k + 1 >= argc) throw std::invalid_argument(a + " needs a value");
        return argv[++k];
      };
      if (a == "--rounds")
        o.rounds = std::stoi(value());
      else if (a == "--steps")
        o.steps = std::stoi(value());
      else if (a == "--warm")
        o.warm = std::stod(value());
      else if (a == "--poses")
        o.poses = std::stoi(value());
      else if (a == "--results")
        o.results = value();
      else if (a == "--csv")
        o.csv = value();
      else if (a == "--only")
        o.only = value();
      else
        return usage();
    }
    if (o.rounds < 1 || o.steps < 1 || o.warm < 0.0 || o.poses < 0)
      throw std::invalid_argument("--rounds, --steps >= 1, --warm, --poses >= 0");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "shape_cost: %s\n", e.what());
    return usage();
  }
  using dem2d::SuperEllipseShape;
  std::filesystem::create_directories(o.results);

  std::vector<Drum> drums;
  for (const Form& f : kForms) {
    if (f.shaped && std::string(f.name).find(o.only) == std::string::npos) continue;
    Drum d;
    d.form = &f;
    d.sim = std::make_unique<dem2d::Simulation>(drum_scene(f, 400));
    d.bodies = d.sim->scene().particles.size();
    while (d.sim->time() < o.warm) d.sim->step();
    drums.push_back(std::move(d));
  }
  const std::size_t nd = drums.size();
  for (int r = 0; r < o.rounds; ++r) {
    for (std::size_t q = 0; q < nd; ++q) {
      Drum& d = drums[(q + static_cast<std::size_t>(r)) % nd];
      SuperEllipseShape::reset_stats();
      const double t0 = bench::thread_cpu_seconds();
      for (int k = 1; k <= o.steps; ++k) d.sim->step(/*end_observed=*/k == o.steps);
      d.ns.push_back(1e9 * (bench::thread_cpu_seconds() - t0) /
                     (static_cast<double>(d.bodies) * o.steps));
      const SuperEllipseShape::Stats& st = SuperEllipseShape::stats();
      d.pair_solves += st.pair_solves;
      d.evaluations += st.pair_iterations;
      d.unconverged += st.pair_unconverged + st.wall_unconverged;
      d.wall_solves += st.wall_solves;
      d.cold += st.pair_cold;
      d.steps += o.steps;
    }
  }

  std::printf("shape_cost: 400 bodies in the thesis drum, %d rounds of %d steps after %.3g s\n",
              o.rounds, o.steps, o.warm);
  std::printf("%-16s %8s %8s %9s %8s %8s %9s %7s %9s %10s %11s\n", "scene", "ns min", "ns q25",
              "ns median", "ns q75", "x discs", "pairs/st", "cold %", "walls/st", "evals/pair",
              "unconverged");
  const std::string path = o.results + "/" + o.csv;
  std::ofstream csv(path);
  csv << "scene,round,ns_per_particle_step_cpu,over_discs,pair_solves_per_step,"
         "evaluations_per_pair_solve,unconverged\n";
  for (const Drum& d : drums) {
    std::vector<double> ratio;
    for (int r = 0; r < o.rounds; ++r) {
      const auto u = static_cast<std::size_t>(r);
      ratio.push_back(d.ns[u] / drums[0].ns[u]);
      csv << '"' << d.form->name << "\"," << r + 1 << ',' << d.ns[u] << ',' << ratio.back() << ','
          << static_cast<double>(d.pair_solves) / static_cast<double>(d.steps) << ','
          << static_cast<double>(d.evaluations) / std::max<double>(1.0, d.pair_solves) << ','
          << d.unconverged << '\n';
    }
    const auto q = [&](double at) { return bench::quantile(d.ns, at); };
    std::printf("%-16s %8.1f %8.1f %9.1f %8.1f %8.1f %9.1f %7.1f %9.1f %10.2f %11lld\n",
                d.form->name, q(0.0), q(0.25), q(0.5), q(0.75), bench::quantile(ratio, 0.5),
                static_cast<double>(d.pair_solves) / static_cast<double>(d.steps),
                100.0 * static_cast<double>(d.cold) / std::max<double>(1.0, d.pair_solves),
                static_cast<double>(d.wall_solves) / static_cast<double>(d.steps),
                static_cast<double>(d.evaluations) / std::max<double>(1.0, d.pair_solves),
                static_cast<long long>(d.unconverged));
  }
  csv.close();
  std::printf(
      "(ns: thread CPU time per particle-step over the rounds; x discs: median over the rounds of "
      "the block's time over the discs' block of the same round; pairs/st, walls/st: superellipse "
      "solves per step; cold %%: pair solves from a cold start (a new contact); evals/pair: "
      "penetration-depth evaluations per pair solve)\nwrote %s\n",
      path.c_str());

  // ---- Tolerance against error: contact_depth, cold and warm, against a cold tol 1e-14 ----
  const double tols[] = {1e-6, 1e-8, 1e-10, 1e-12};
  const std::string tpath = o.results + "/shape_cost_tolerance.csv";
  std::ofstream tcsv(tpath);
  tcsv << "shape,tol,start,angle_error_median,angle_error_max,depth_error_max_relative,"
          "evaluations_per_solve,ns_per_solve,unconverged\n";
  std::printf(
      "\ncontact_depth against its tolerance: %d overlapping poses per shape (overlap "
      "0.1-5 %% of the bounding radius), error against tol 1e-14\n",
      o.poses);
  std::printf("%-16s %7s %5s %12s %12s %12s %8s %9s %6s\n", "shape", "tol", "start", "angle median",
              "angle max", "depth max", "evals", "ns/solve", "uncv");
  for (const Form& f : kForms) {
    if (!f.shaped || o.poses == 0 || std::string(f.name).find(o.only) == std::string::npos)
      continue;
    const dem2d::SuperEllipse s = scaled_form(f, 0.1);
    const std::vector<Pose> poses = overlapping_poses(s, o.poses, 11);
    dem2d::SolveOptions tight;
    tight.tol = 1e-14;
    tight.max_iter = 100;
    std::vector<dem2d::SuperPairContact> ref;
    for (const Pose& p : poses) ref.push_back(dem2d::contact_depth(s, p.i, s, p.j, {}, tight));
    for (const double tol : tols) {
      for (const bool warm : {false, true}) {
        dem2d::SolveOptions opt;
        opt.tol = tol;
        // Warm: the pose a step on (j moved by 1e-4 m and turned by 1e-4 rad), started from the
        // reference normal of the pose before; its own reference solved afresh.
        std::vector<Pose> at = poses;
        std::vector<dem2d::SuperPairContact> want = ref;
        if (warm)
          for (std::size_t k = 0; k < at.size(); ++k) {
            at[k].j.centre += dem2d::Vec2{1e-4, -0.5e-4};
            at[k].j.theta += 1e-4;
            want[k] = dem2d::contact_depth(s, at[k].i, s, at[k].j, {}, tight);
          }
        std::vector<double> err;
        double depth_err = 0.0, evals = 0.0;
        int unconverged = 0, solved = 0;
        double best = 1e300;
        for (int round = 0; round < 5; ++round) {
          err.clear();
          evals = 0.0;
          unconverged = solved = 0;
          const double t0 = bench::thread_cpu_seconds();
          for (std::size_t k = 0; k < at.size(); ++k) {
            dem2d::DepthStart start;
            start.warm = warm;
            start.phi = ref[k].angle;
            const dem2d::SuperPairContact c =
                dem2d::contact_depth(s, at[k].i, s, at[k].j, start, opt);
            if (!(want[k].delta > 0.0) || !(c.delta > 0.0)) continue;
            ++solved;
            err.push_back(angle_between(c.n, want[k].n));
            depth_err = std::max(depth_err, std::abs(c.delta - want[k].delta) / want[k].delta);
            evals += c.depth_iterations;
            unconverged += c.converged ? 0 : 1;
          }
          best = std::min(
              best, 1e9 * (bench::thread_cpu_seconds() - t0) / static_cast<double>(at.size()));
        }
        const double med = err.empty() ? 0.0 : bench::quantile(err, 0.5);
        const double worst = err.empty() ? 0.0 : bench::quantile(err, 1.0);
        const double per = evals / std::max(1, solved);
        std::printf("%-16s %7.0e %5s %12.3g %12.3g %12.3g %8.2f %9.1f %6d\n", f.name, tol,
                    warm ? "warm" : "cold", med, worst, depth_err, per, best, unconverged);
        tcsv << '"' << f.name << "\"," << tol << ',' << (warm ? "warm" : "cold") << ',' << med
             << ',' << worst << ',' << depth_err << ',' << per << ',' << best << ',' << unconverged
             << '\n';
      }
    }
  }
  std::printf(
      "(angle: |normal angle - reference| in rad; depth: max relative error of the "
      "overlap; evals: support-point evaluations per solve; ns/solve: the fastest of 5 "
      "passes over the poses, thread CPU time)\nwrote %s\n",
      tpath.c_str());
  return 0;
}
