// Neighbour search (core/contact/neighbors.hpp): the cell-grid Verlet lists hold exactly the
// brute-force candidate set, contact histories survive rebuilds and reordering of the particle
// store, and during a run every actual contact is found.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <numeric>
#include <utility>
#include <vector>

#include "core/base/random.hpp"
#include "core/contact/neighbors.hpp"
#include "core/geometry/walls.hpp"
#include "core/run/simulation.hpp"
#include "core/shape/disc.hpp"
#include "support/scenes.hpp"
#include "support/thesis.hpp"

namespace dem2d {
namespace {

using IdPair = std::pair<std::int64_t, std::int64_t>;

MaterialSpec steel() { return testing_support::thesis_steel(); }

// Brute force: every (particle id, wall element) whose gap is below `skin` (delta > -skin).
std::vector<IdPair> brute_force_wall_pairs(const ParticleStore& p, const Walls& walls,
                                           double skin) {
  std::vector<IdPair> out;
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    for (int e = 0; e < static_cast<int>(walls.elements().size()); ++e)
      if (Disc::wall(walls, e, p.pos[k], p.radius[k]).delta > -skin) out.emplace_back(p.id[k], e);
  std::sort(out.begin(), out.end());
  return out;
}

// The listed pairs in key order (the list itself is in storage order when the particles are
// not stored in id order).
std::vector<IdPair> listed_pairs(const PairList& pl) {
  std::vector<IdPair> out;
  for (std::size_t t = 0; t < pl.size(); ++t)
    out.emplace_back(pl.id_i[pl.entry(t)], pl.id_j[pl.entry(t)]);
  return out;
}

// A list in storage order: entries by their lower local index, and every owned particle's
// force records naming each of its pairs once, in the order of the partners' ids.
void expect_storage_order(const ParticleStore& p, const PairList& pl) {
  ASSERT_FALSE(pl.canonical());
  for (std::size_t k = 1; k < pl.size(); ++k)
    EXPECT_LE(std::min(pl.i[k - 1], pl.j[k - 1]), std::min(pl.i[k], pl.j[k]));
  ASSERT_EQ(pl.record_start.size(), p.n_owned() + 1);
  std::size_t records = 0;
  for (std::size_t q = 0; q < p.n_owned(); ++q) {
    std::vector<std::int64_t> partners;
    for (std::int32_t s = pl.record_start[q]; s < pl.record_start[q + 1]; ++s) {
      const std::int32_t r = pl.records[s];
      const std::size_t k = static_cast<std::size_t>(r / 2);
      const std::int32_t self = r % 2 ? pl.j[k] : pl.i[k];
      const std::int32_t other = r % 2 ? pl.i[k] : pl.j[k];
      EXPECT_EQ(static_cast<std::size_t>(self), q);
      partners.push_back(p.id[other]);
      ++records;
    }
    EXPECT_TRUE(std::is_sorted(partners.begin(), partners.end())) << "particle " << p.id[q];
  }
  EXPECT_EQ(records, 2 * pl.size());  // no ghosts here: both ends of every pair are owned
}

std::vector<IdPair> listed_wall_pairs(const WallPairList& wl) {
  std::vector<IdPair> out;
  for (std::size_t k = 0; k < wl.size(); ++k) out.emplace_back(wl.id[k], wl.element[k]);
  return out;
}

enum class Shell { kNone, kCircle, kPolygon };

struct Config {
  double size_ratio;  // r_max / r_min
  Shell shell;
  double skin;
  bool shuffled_ids;
  bool outliers;  // a few particles far away: a huge bounding box (cells enlarged)
  NeighborSearch::Levels levels = NeighborSearch::Levels::kAuto;
};

// The walls of a configuration: a drum (with lifters if polygonal) or two wall segments.
Scene config_scene(const Config& c) {
  Scene s;
  s.materials.push_back(steel());
  if (c.shell != Shell::kNone) {
    s.drum.present = true;
    s.drum.radius = 1.5;
    s.drum.sides = c.shell == Shell::kPolygon ? 16 : 0;
    s.drum.angle = 0.3;
    s.drum.material = "steel";
    if (c.shell == Shell::kPolygon) {
      LifterSpec l;
      l.count = 4;
      l.height = 0.1;
      l.width = 0.08;
      s.drum.lifters.push_back(l);
    }
  } else {
    s.walls.push_back(testing_support::segment({-1.6, -1.6}, {1.6, -1.6}, "steel"));
    s.walls.push_back(testing_support::segment({-1.6, 1.0}, {0.5, -0.4}, "steel"));
  }
  return s;
}

// Random configuration (overlaps allowed: the search does not care) of 600 particles.
void check_config(const Config& c) {
  const Walls walls(config_scene(c));
  const double r_max = 0.06, r_min = r_max / c.size_ratio;
  const int n = 600;
  std::vector<std::int64_t> ids(n);
  std::iota(ids.begin(), ids.end(), 0);
  if (c.shuffled_ids)
    for (int k = n - 1; k > 0; --k)
      std::swap(ids[k], ids[static_cast<int>(random_uniform(5, 1, k) * (k + 1))]);
  ParticleStore p;
  for (int k = 0; k < n; ++k) {
    const double r = r_min + (r_max - r_min) * random_uniform(5, 2, k);
    // Uniform in a disc of radius 1.55 (the shell's reach, so some cross it) or a 3.2 m box.
    Vec2 x;
    if (c.shell != Shell::kNone) {
      const double rho = 1.55 * std::sqrt(random_uniform(5, 3, k)),
                   phi = 2.0 * std::numbers::pi * random_uniform(5, 4, k);
      x = {rho * std::cos(phi), rho * std::sin(phi)};
    } else {
      x = {3.2 * random_uniform(5, 3, k) - 1.6, 3.2 * random_uniform(5, 4, k) - 1.6};
    }
    p.add(ids[k], 0, r, 7800.0, x, {}, 0.0);
  }
  if (c.outliers) {
    p.add(n, 0, r_max, 7800.0, {60.0, 45.0}, {}, 0.0);
    p.add(n + 1, 0, r_min, 7800.0, {-80.0, 3.0}, {}, 0.0);
    p.add(n + 2, 0, r_min, 7800.0, {-80.0, 3.0 + r_min}, {}, 0.0);  // a pair out there
  }

  NeighborSearch search;
  search.set_levels(c.levels);
  PairList pairs;
  pairs.width = 2;  // e.g. a tangential and a rolling spring
  WallPairList wall_pairs;
  search.build(p, walls, c.skin, pairs, wall_pairs);
  if (c.levels == NeighborSearch::Levels::kNever || c.size_ratio < 2.0) {
    EXPECT_EQ(search.levels_used(), 1);
  } else if (c.levels == NeighborSearch::Levels::kAlways) {
    EXPECT_EQ(search.levels_used(),
              std::min(8, static_cast<int>(std::ceil(std::log2(c.size_ratio - 1e-9)))));
  }
  const std::vector<IdPair> got = listed_pairs(pairs);
  const std::vector<IdPair> want = NeighborSearch::brute_force_pairs(p, c.skin);
  SCOPED_TRACE(testing::Message() << "size ratio " << c.size_ratio << ", shell "
                                  << static_cast<int>(c.shell) << ", skin " << c.skin
                                  << ", shuffled ids " << c.shuffled_ids << ", outliers "
                                  << c.outliers);
  EXPECT_GT(want.size(), 100u);
  EXPECT_EQ(got, want);
  // Canonical order: lower id first, sorted; local indices consistent with the ids.
  EXPECT_TRUE(std::is_sorted(got.begin(), got.end()));
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    EXPECT_LT(pairs.id_i[k], pairs.id_j[k]);
    EXPECT_EQ(p.id[pairs.i[k]], pairs.id_i[k]);
    EXPECT_EQ(p.id[pairs.j[k]], pairs.id_j[k]);
  }
  EXPECT_EQ(pairs.history.size(), pairs.size() * pairs.width);  // the declared slots per pair
  if (c.shuffled_ids) {
    expect_storage_order(p, pairs);
  } else {
    EXPECT_TRUE(pairs.canonical());
  }

  std::vector<IdPair> got_w = listed_wall_pairs(wall_pairs);
  EXPECT_TRUE(std::is_sorted(got_w.begin(), got_w.end()));
  const std::vector<IdPair> want_w = brute_force_wall_pairs(p, walls, c.skin);
  EXPECT_EQ(got_w, want_w);
  for (std::size_t k = 0; k < wall_pairs.size(); ++k)
    EXPECT_EQ(p.id[wall_pairs.particle[k]], wall_pairs.id[k]);
  if (c.shell != Shell::kNone || c.skin > 0.0) {
    EXPECT_GT(want_w.size(), 10u);
  }
}

TEST(Neighbors, CandidatesEqualBruteForceForRandomConfigurations) {
  for (double ratio : {1.0, 10.0, 400.0})
    for (Shell shell : {Shell::kNone, Shell::kCircle, Shell::kPolygon})
      for (double skin : {0.0, 0.02}) check_config({ratio, shell, skin, false, false});
  check_config({10.0, Shell::kPolygon, 0.02, true, false});
  check_config({1.0, Shell::kNone, 0.01, true, true});
  check_config({400.0, Shell::kCircle, 0.02, true, false});
  // Size levels forced on and off: the same lists (8 levels at 400:1, the smallest taking
  // everything below r_max / 128).
  for (double ratio : {3.0, 10.0, 400.0})
    for (auto levels : {NeighborSearch::Levels::kAlways, NeighborSearch::Levels::kNever}) {
      check_config({ratio, Shell::kCircle, 0.02, true, false, levels});
      check_config({ratio, Shell::kNone, 0.0, false, true, levels});
    }
  check_config({10.0, Shell::kNone, 0.0, false, true});
}

// ---------------------------------------------------------------------------------------------
// Contact histories: ball 0 slides on a floor, ball 1 sits on ball 0's shoulder spinning (a
// sliding pair contact), ball 2 rests on the floor apart. After 300 steps every history is loaded;
// a forced rebuild, then a reversal of the store's order and a rebuild, must keep every history
// (keyed by ids), and the run must continue bit for bit as a run that was never reordered.

Scene sliding_scene() {
  Scene s;
  s.deck_path = "test_neighbors";
  s.materials.push_back(steel());
  s.run.dt_auto = true;
  s.walls.push_back(testing_support::segment({-5.0, 0.0}, {5.0, 0.0}, "steel"));
  auto add = [&](Vec2 x, Vec2 v, double spin) {
    s.particles.push_back(testing_support::ball("steel", 0.1, x, v, spin));
  };
  // Overlaps of 2 um (the steel Hertz overlap under one ball's weight is 4.7 um).
  const double y0 = 0.1 - 2e-6, d = 0.2 - 2e-6, a = std::numbers::pi / 3.0;
  add({0.0, y0}, {1.0, 0.0}, 0.0);
  add({d * std::cos(a), y0 + d * std::sin(a)}, {1.0, 0.0}, 30.0);
  add({2.0, y0}, {0.0, 0.0}, 0.0);
  return s;
}

// The scene's model (hertz-mindlin with epsd rolling) declares two history slots: the
// tangential spring xi and the rolling spring m_roll.
struct ContactHistory {
  double xi = 0.0;
  double m_roll = 0.0;
};
struct Histories {
  std::vector<std::pair<IdPair, ContactHistory>> pairs, walls;
};
Histories histories(const Simulation& sim) {
  Histories h;
  const PairList& pl = sim.pairs();
  EXPECT_EQ(pl.width, 2u);
  for (std::size_t k = 0; k < pl.size(); ++k) {
    const ContactHistory c{pl.history_of(k)[0], pl.history_of(k)[1]};
    if (c.xi != 0.0 || c.m_roll != 0.0) h.pairs.push_back({{pl.id_i[k], pl.id_j[k]}, c});
  }
  const WallPairList& wl = sim.wall_pairs();
  for (std::size_t k = 0; k < wl.size(); ++k) {
    const ContactHistory c{wl.history_of(k)[0], wl.history_of(k)[1]};
    if (c.xi != 0.0 || c.m_roll != 0.0) h.walls.push_back({{wl.id[k], wl.element[k]}, c});
  }
  return h;
}
void expect_same(const Histories& a, const Histories& b, const char* when) {
  ASSERT_EQ(a.pairs.size(), b.pairs.size()) << when;
  ASSERT_EQ(a.walls.size(), b.walls.size()) << when;
  for (std::size_t k = 0; k < a.pairs.size(); ++k) {
    EXPECT_EQ(a.pairs[k].first, b.pairs[k].first) << when;
    EXPECT_EQ(a.pairs[k].second.xi, b.pairs[k].second.xi) << when;
    EXPECT_EQ(a.pairs[k].second.m_roll, b.pairs[k].second.m_roll) << when;
  }
  for (std::size_t k = 0; k < a.walls.size(); ++k) {
    EXPECT_EQ(a.walls[k].first, b.walls[k].first) << when;
    EXPECT_EQ(a.walls[k].second.xi, b.walls[k].second.xi) << when;
    EXPECT_EQ(a.walls[k].second.m_roll, b.walls[k].second.m_roll) << when;
  }
}

TEST(Neighbors, ContactHistorySurvivesRebuildAndReordering) {
  Simulation sim(sliding_scene());
  Simulation reference(sliding_scene());
  for (int k = 0; k < 300; ++k) {
    sim.step();
    reference.step();
  }
  const Histories before = histories(sim);
  // Loaded springs: the 0-1 pair and ball 0 on the floor (ball 2 rests: its spring is unloaded).
  ASSERT_EQ(before.pairs.size(), 1u);
  EXPECT_EQ(before.pairs[0].first, IdPair(0, 1));
  ASSERT_EQ(before.walls.size(), 1u);
  EXPECT_EQ(before.walls[0].first, IdPair(0, 0));
  EXPECT_NE(before.walls[0].second.xi, 0.0);
  EXPECT_NE(before.pairs[0].second.xi, 0.0);
  EXPECT_NE(before.pairs[0].second.m_roll, 0.0);
  const std::int64_t builds = sim.neighbor_builds();

  sim.rebuild();
  reference.rebuild();
  EXPECT_EQ(sim.neighbor_builds(), builds + 1);
  expect_same(before, histories(sim), "after a forced rebuild");

  std::vector<std::size_t> order(sim.particles().n_owned());
  std::iota(order.rbegin(), order.rend(), 0);  // reverse
  sim.particles().permute(order);
  EXPECT_EQ(sim.particles().id[0], 2);
  sim.rebuild();
  expect_same(before, histories(sim), "after reversing the store and rebuilding");

  for (int k = 0; k < 2000; ++k) {
    sim.step();
    reference.step();
  }
  const ParticleStore& p = sim.particles();
  const ParticleStore& q = reference.particles();
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    const std::size_t r = static_cast<std::size_t>(p.id[k]);  // the reference keeps id order
    ASSERT_EQ(q.id[r], p.id[k]);
    EXPECT_EQ(p.pos[k], q.pos[r]) << "particle " << p.id[k];
    EXPECT_EQ(p.vel[k], q.vel[r]) << "particle " << p.id[k];
    EXPECT_EQ(p.omega[k], q.omega[r]) << "particle " << p.id[k];
  }
  expect_same(histories(reference), histories(sim), "2000 steps later");
}

// ---------------------------------------------------------------------------------------------
// During a run the contacts found (overlapping pairs of the Verlet lists) are exactly the
// brute-force overlapping set: a bed of 300 polydisperse balls (r 0.03-0.06 m) stirred at up to
// 3 m/s in a 16-gon with lifters turning at 1.8 rad/s; checked at every step for 2000 steps.
TEST(Neighbors, ContactSetEqualsBruteForceDuringARun) {
  Scene s;
  s.deck_path = "test_neighbors";
  s.materials.push_back(steel());
  s.drum.present = true;
  s.drum.radius = 1.5;
  s.drum.speed = 1.8;
  s.drum.sides = 16;
  s.drum.material = "steel";
  LifterSpec l;
  l.count = 6;
  l.height = 0.15;
  l.width = 0.1;
  s.drum.lifters.push_back(l);
  FillSpec f;
  f.material = "steel";
  f.count = 300;
  f.radius_min = 0.03;
  f.radius_max = 0.06;
  f.region = FillRegion::kBottom;
  s.fills.push_back(f);
  s.run.dt_auto = false;
  s.run.dt = 1e-5;
  Simulation sim(s);
  ParticleStore& p = sim.particles();
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    p.vel[k] = {6.0 * random_uniform(9, 1, 2 * k) - 3.0,
                6.0 * random_uniform(9, 1, 2 * k + 1) - 3.0};
  const std::int64_t builds0 = sim.neighbor_builds();
  std::int64_t observed = 0, observed_wall = 0;
  for (int step = 1; step <= 2000; ++step) {
    sim.step();
    std::vector<IdPair> found;
    const PairList& pl = sim.pairs();
    for (std::size_t k = 0; k < pl.size(); ++k) {
      const double rs = p.radius[pl.i[k]] + p.radius[pl.j[k]];
      if (norm2(p.pos[pl.j[k]] - p.pos[pl.i[k]]) < rs * rs)
        found.emplace_back(pl.id_i[k], pl.id_j[k]);
    }
    ASSERT_EQ(found, NeighborSearch::brute_force_pairs(p, 0.0)) << "step " << step;
    std::vector<IdPair> found_w;
    const WallPairList& wl = sim.wall_pairs();
    for (std::size_t k = 0; k < wl.size(); ++k)
      if (Disc::wall(sim.walls(), wl.element[k], p.pos[wl.particle[k]], p.radius[wl.particle[k]])
              .delta > 0.0)
        found_w.emplace_back(wl.id[k], wl.element[k]);
    ASSERT_EQ(found_w, brute_force_wall_pairs(p, sim.walls(), 0.0)) << "step " << step;
    ASSERT_EQ(static_cast<std::int64_t>(found.size() + found_w.size()), sim.last_totals().contacts)
        << "step " << step;
    observed += static_cast<std::int64_t>(found.size());
    observed_wall += static_cast<std::int64_t>(found_w.size());
  }
  const std::int64_t builds = sim.neighbor_builds() - builds0;
  std::cout << "[ neighbours ] 2000 steps: " << builds << " rebuilds, " << observed
            << " particle and " << observed_wall << " wall contact-steps checked\n";
  EXPECT_GE(builds, 5) << "the lists were rebuilt during the run";
  EXPECT_GT(observed, 2000);
  EXPECT_GT(observed_wall, 50);
}

}  // namespace
}  // namespace dem2d
