// Counter-based random numbers: a draw is a pure function of (run seed, key, counter), so the
// same particle gets the same draw whatever rank owns it and in whatever order draws happen
// (docs/architecture.md, "Reproducibility"). The mixer is SplitMix64's finaliser applied in a
// chain.
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>

namespace dem2d {

constexpr std::uint64_t mix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

constexpr std::uint64_t random_bits(std::uint64_t seed, std::uint64_t key, std::uint64_t counter) {
  return mix64(mix64(mix64(seed) ^ key) ^ counter);
}

// Uniform in [0, 1) with 53 random bits.
constexpr double random_uniform(std::uint64_t seed, std::uint64_t key, std::uint64_t counter) {
  return static_cast<double>(random_bits(seed, key, counter) >> 11) * 0x1.0p-53;
}

// Standard normal by Box-Muller from two consecutive counters.
inline double random_normal(std::uint64_t seed, std::uint64_t key, std::uint64_t counter) {
  const double u1 = 1.0 - random_uniform(seed, key, 2 * counter);  // (0, 1]
  const double u2 = random_uniform(seed, key, 2 * counter + 1);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

}  // namespace dem2d
