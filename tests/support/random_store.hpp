// A particle store filled with unrelated random values in every field a step reads (positions,
// velocities, spins, accelerations, forces, torques, elastic forces), and a bitwise comparison:
// for the tests that compare two ways of computing the same step loop.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <random>

#include "core/shape/particles.hpp"

namespace dem2d::testing_support {

inline void fill_random_store(ParticleStore& p, std::size_t n, std::uint32_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::size_t k = 0; k < n; ++k) {
    p.add(static_cast<std::int64_t>(k), static_cast<std::int32_t>(k % 3), 0.01 + 0.005 * u(rng),
          7800.0, {u(rng), u(rng)}, {u(rng), u(rng)}, 10.0 * u(rng));
    p.acc[k] = {9.81 * u(rng), 9.81 * u(rng)};
    p.alpha[k] = 100.0 * u(rng);
    p.theta[k] = u(rng);
    p.force[k] = {u(rng), u(rng)};
    p.torque[k] = 1e-3 * u(rng);
    p.elastic_force[k] = {0.5 * u(rng), 0.5 * u(rng)};
  }
}

template <class T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

}  // namespace dem2d::testing_support
