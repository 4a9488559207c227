// Two runs of one scene compared particle by particle.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>
#include <map>
#include <vector>

#include "core/run/simulation.hpp"

namespace dem2d::testing_support {

// Every field of every owned particle, bit for bit, matched by id.
inline void expect_same_particles(const Simulation& a, const Simulation& b) {
  const ParticleStore& p = a.particles();
  const ParticleStore& q = b.particles();
  ASSERT_EQ(p.n_owned(), q.n_owned());
  std::map<std::int64_t, std::size_t> in_q;
  for (std::size_t k = 0; k < q.n_owned(); ++k) in_q[q.id[k]] = k;
  for (std::size_t f = 0; f < p.fields().size(); ++f) {
    const FieldBase& fa = *p.fields()[f];
    const FieldBase& fb = *q.fields()[f];
    ASSERT_EQ(fa.name(), fb.name());
    const std::size_t w = fa.bytes_per_item();
    std::vector<std::byte> x(w), y(w);
    int differ = 0;
    for (std::size_t m = 0; m < p.n_owned(); ++m) {
      ASSERT_TRUE(in_q.contains(p.id[m])) << "particle " << p.id[m];
      fa.pack(m, x.data());
      fb.pack(in_q[p.id[m]], y.data());
      differ += std::memcmp(x.data(), y.data(), w) != 0;
    }
    EXPECT_EQ(differ, 0) << "field " << fa.name();
  }
}

// The energy ledger of two runs (series.csv's dissipated energy, drive work, kinetic and
// elastic energy), bit for bit.
inline void expect_same_ledger(const Simulation& a, const Simulation& b) {
  const auto same = [](double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; };
  const SeriesRow p = a.diagnostics(), q = b.diagnostics();
  EXPECT_TRUE(same(p.dissipated_energy, q.dissipated_energy));
  EXPECT_TRUE(same(p.drive_work, q.drive_work));
  EXPECT_TRUE(same(p.kinetic_energy, q.kinetic_energy));
  EXPECT_TRUE(same(p.elastic_energy, q.elastic_energy));
}

}  // namespace dem2d::testing_support
