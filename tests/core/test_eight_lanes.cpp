// EightLanes (core/fast/simd.hpp): the pair loop's energy sums are the same bits whatever the
// build's vector width. The Release build runs this with 8-wide packs (AVX-512 here), the
// sanitizer build (no -march=native) with 2-wide ones; both must give the eight-lane sum.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <random>
#include <vector>

#include "core/fast/simd.hpp"

namespace dem2d {
namespace {

// Values over 16 decades and both signs: every other order of the additions gives other bits.
std::vector<double> mixed_values(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 gen(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<double> v(n);
  for (double& x : v) x = unit(gen) * std::pow(10.0, std::round(8.0 * unit(gen)));
  return v;
}

// What the pair loop does: packs of kPackSize contacts from 0 on (the batch padded with zeros).
double lane_sum(const std::vector<double>& v) {
  const std::size_t n = (v.size() + kPackSize - 1) / kPackSize * kPackSize;
  std::vector<double> padded(v);
  padded.resize(n, 0.0);
  EightLanes sum;
  for (std::size_t c = 0; c < n; c += kPackSize)
    sum.add(c, Pack(padded.data() + c, stdx::element_aligned));
  return sum.sum();
}

// Contact c into lane c mod 8 in order, the lanes added as stdx::reduce adds a pack of 8.
double eight_lane_reference(const std::vector<double>& v) {
  double lane[8] = {};
  for (std::size_t c = 0; c < v.size(); ++c) lane[c % 8] += v[c];
  return ((lane[0] + lane[4]) + (lane[2] + lane[6])) + ((lane[1] + lane[5]) + (lane[3] + lane[7]));
}

TEST(EightLanes, AddsEachContactInLaneCMod8WhateverThePackWidth) {
  for (std::size_t n : {1u, 7u, 8u, 9u, 64u, 203u, 512u}) {
    const std::vector<double> v = mixed_values(n, 17 + n);
    EXPECT_EQ(lane_sum(v), eight_lane_reference(v)) << n << " contacts, packs of " << kPackSize;
  }
}

// The order is not any order: adding the same values one after the other gives other bits (so
// the test above can tell a wrong lane or a wrong final order).
TEST(EightLanes, TheOrderShowsInTheBits) {
  const std::vector<double> v = mixed_values(203, 220);
  double in_turn = 0.0;
  for (double x : v) in_turn += x;
  EXPECT_NE(in_turn, eight_lane_reference(v));
}

// With packs of 8 the sum is what one pack and stdx::reduce gave before (the Release build's
// energies kept their bits).
TEST(EightLanes, WithPacksOfEightItIsTheReduceOfOnePack) {
  if (kPackSize != 8) GTEST_SKIP() << "packs of " << kPackSize << " here";
  const std::vector<double> v = mixed_values(203, 5);
  Pack one(0.0);
  std::vector<double> padded(v);
  padded.resize(208, 0.0);
  for (std::size_t c = 0; c < padded.size(); c += 8)
    one += Pack(padded.data() + c, stdx::element_aligned);
  EXPECT_EQ(lane_sum(v), stdx::reduce(one));
}

}  // namespace
}  // namespace dem2d
