// The superellipse's contact solves (src/core/shape/superellipse.hpp), ns each: a pair by the
// penetration depth (and the midway point) from a cold start and warm-started from its own midway
// point, and a body against a segment (its face, and past its end) and inside a circle. The poses:
// 64 pairs of random superellipses (aspect 1-4, exponent 2-10, random angles) overlapping by about
// 1 % of their size along a random direction.
//
//   build/bench/bm_superellipse [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "core/shape/superellipse.hpp"

namespace dem2d {
namespace {

struct Pose {
  SuperEllipse si, sj;
  SuperPose pi, pj;
  Vec2 warm;
};

std::vector<Pose> poses() {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto body = [&] {
    const double a = 0.05, aspect = 1.0 + 3.0 * u(rng), n = 2.0 + 8.0 * u(rng);
    return SuperEllipse{a, a / aspect, n};
  };
  std::vector<Pose> out;
  while (out.size() < 64) {
    Pose p{body(), body(), {{0.0, 0.0}, 2.0 * std::numbers::pi * u(rng)}, {}, {}};
    const double t = 2.0 * std::numbers::pi * u(rng);
    const Vec2 dir{std::cos(t), std::sin(t)};
    p.pj.theta = 2.0 * std::numbers::pi * u(rng);
    // Move j in from far along dir until the solve reports about 1 % of the smaller size.
    const double size = std::min(bounding_radius(p.si), bounding_radius(p.sj));
    double d = bounding_radius(p.si) + bounding_radius(p.sj);
    SuperPairContact c{};
    for (int k = 0; k < 200 && !(c.converged && c.delta > 0.01 * size); ++k) {
      d -= 0.002 * size;
      p.pj.centre = d * dir;
      c = contact_pair(p.si, p.pi, p.sj, p.pj);
    }
    if (!c.converged || !(c.delta > 0.0)) continue;
    p.warm = c.midway;
    out.push_back(p);
  }
  return out;
}

void PairCold(benchmark::State& state) {
  const std::vector<Pose> p = poses();
  std::size_t k = 0;
  for (auto _ : state) {
    const Pose& x = p[k++ % p.size()];
    benchmark::DoNotOptimize(contact_pair(x.si, x.pi, x.sj, x.pj).delta);
  }
}
BENCHMARK(PairCold);

void PairWarm(benchmark::State& state) {
  const std::vector<Pose> p = poses();
  std::size_t k = 0;
  for (auto _ : state) {
    const Pose& x = p[k++ % p.size()];
    benchmark::DoNotOptimize(contact_pair(x.si, x.pi, x.sj, x.pj, &x.warm).delta);
  }
}
BENCHMARK(PairWarm);

void Segment(benchmark::State& state) {
  const std::vector<Pose> p = poses();
  std::size_t k = 0;
  for (auto _ : state) {
    const Pose& x = p[k++ % p.size()];
    benchmark::DoNotOptimize(
        contact_segment(x.si, {0.0, 0.0}, x.pi.theta, {-1.0, -0.04}, {1.0, -0.04}).contact.g.delta);
  }
}
BENCHMARK(Segment);

// The segment ending under the bodies: the deepest point often projects past its end (about half
// of the poses), where the end's 1D minimisation runs.
void SegmentEnd(benchmark::State& state) {
  const std::vector<Pose> p = poses();
  std::size_t k = 0;
  for (auto _ : state) {
    const Pose& x = p[k++ % p.size()];
    benchmark::DoNotOptimize(
        contact_segment(x.si, {0.0, 0.0}, x.pi.theta, {-1.0, -0.04}, {0.0, -0.04}).contact.g.delta);
  }
}
BENCHMARK(SegmentEnd);

void InsideCircle(benchmark::State& state) {
  const std::vector<Pose> p = poses();
  std::size_t k = 0;
  for (auto _ : state) {
    const Pose& x = p[k++ % p.size()];
    benchmark::DoNotOptimize(
        contact_inside_circle(x.si, {0.0, 0.0}, x.pi.theta, {0.0, 0.46}, 0.5).contact.g.delta);
  }
}
BENCHMARK(InsideCircle);

}  // namespace
}  // namespace dem2d
