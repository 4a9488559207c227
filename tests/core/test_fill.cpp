// Initial placement ([[fill]], [[particle]]) and pair coefficients ([[interaction]]).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/base/errors.hpp"
#include "core/contact/contact_models.hpp"
#include "core/contact/materials.hpp"
#include "core/run/simulation.hpp"
#include "core/setup/fill.hpp"
#include "core/shape/disc.hpp"
#include "core/shape/superellipse.hpp"
#include "support/scenes.hpp"

namespace dem2d {
namespace {

// Steel (G = 8e10) with restitution 0.5, sliding friction 0.2, rolling friction 0.02.
MaterialSpec steel(const std::string& name = "steel") {
  return testing_support::make_material(name, 7800, 2e11, 0.25, 0.5, 0.2, 0.02);
}

Scene drum_scene(int sides = 0) {
  Scene s;
  s.deck_path = "test.in";
  s.materials.push_back(steel());
  s.drum.present = true;
  s.drum.radius = 1.0;
  s.drum.sides = sides;
  s.drum.material = "steel";
  return s;
}

FillSpec fill(std::int64_t count, double r_min, double r_max, FillRegion region) {
  return testing_support::fill_spec("steel", count, r_min, r_max, region);
}

struct Placed {
  Walls walls;
  ParticleStore p;
};

// Checks no two particles overlap and every particle is inside the shell, off every wall.
void expect_valid_packing(const Scene& s, const ParticleStore& p, const Walls& walls) {
  for (std::size_t a = 0; a < p.size(); ++a) {
    for (std::size_t b = a + 1; b < p.size(); ++b)
      ASSERT_GE(norm(p.pos[a] - p.pos[b]), p.radius[a] + p.radius[b]) << "ids " << a << ", " << b;
    for (int e = 0; e < static_cast<int>(walls.elements().size()); ++e)
      ASSERT_LE(Disc::wall(walls, e, p.pos[a], p.radius[a]).delta, 1e-12)
          << "id " << a << " wall " << e;
    if (s.drum.present) {
      ASSERT_LE(norm(p.pos[a] - s.drum.center) + p.radius[a], s.drum.radius + 1e-12);
    }
  }
}

TEST(Fill, CountMonodisperseBottomIsLowestAndNonOverlapping) {
  Scene s = drum_scene();
  s.fills.push_back(fill(200, 0.03, 0.03, FillRegion::kBottom));
  Walls walls(s);
  ParticleStore p;
  place_particles(s, walls, p);
  ASSERT_EQ(p.size(), 200u);
  expect_valid_packing(s, p, walls);
  double y_max = -1e9;
  for (std::size_t k = 0; k < p.size(); ++k) {
    EXPECT_EQ(p.id[k], static_cast<std::int64_t>(k));
    EXPECT_DOUBLE_EQ(p.radius[k], 0.03);
    EXPECT_DOUBLE_EQ(p.mass[k], 4.0 / 3.0 * std::numbers::pi * 0.03 * 0.03 * 0.03 * 7800);
    EXPECT_DOUBLE_EQ(1.0 / p.inv_inertia[k], 0.4 * p.mass[k] * 0.03 * 0.03);
    y_max = std::max(y_max, p.pos[k].y);
  }
  // 200 spheres of cross-section 2.83e-3 m^2 cover 0.57 m^2 of the lattice: the lower part of
  // a 3.14 m^2 drum, well below the centre.
  EXPECT_LT(y_max, -0.2);
}

// A fill of superellipses: each has the mass and form the deck asks for (the sphere of its
// volume-equivalent radius), a random angle, and no two overlap, nor any the shell or a bar.
TEST(Fill, SuperellipsesHaveTheirEquivalentSpheresMassAndDoNotOverlap) {
  Scene s = drum_scene();
  s.drum.lifters.push_back(
      {.count = 8, .height = 0.08, .width = 0.06, .angle = 0.0, .material = ""});
  FillSpec f = fill(150, 0.02, 0.04, FillRegion::kBottom);
  f.shape = ParticleShape::kSuperellipse;
  f.aspect = 0.4;
  f.exponent = 6.0;
  s.fills.push_back(f);
  FillSpec e = fill(60, 0.03, 0.03, FillRegion::kBottom);
  e.shape = ParticleShape::kSuperellipse;
  e.aspect = 0.7;
  e.mix = true;
  s.fills.push_back(e);
  Walls walls(s);
  ParticleStore p;
  p.enable_shape();
  place_particles(s, walls, p);
  ASSERT_EQ(p.size(), 210u);
  double c2 = 0.0, s2 = 0.0;
  int fill0 = 0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const SuperEllipse sk{(*p.semi_a())[k], (*p.semi_b())[k], (*p.exponent())[k]};
    const bool first = sk.n == 6.0;
    fill0 += first;
    EXPECT_NEAR(sk.b / sk.a, first ? 0.4 : 0.7, 1e-15);
    EXPECT_EQ(sk.n, first ? 6.0 : 2.0);
    // The mass of the sphere of its volume-equivalent radius, in the fill's range.
    const double r = std::cbrt(p.mass[k] / (7800 * 4.0 / 3.0 * std::numbers::pi));
    EXPECT_NEAR(equivalent_radius(sk), r, 1e-14);
    EXPECT_GE(r, (first ? 0.02 : 0.03) - 1e-14);
    EXPECT_LE(r, (first ? 0.04 : 0.03) + 1e-14);
    EXPECT_NEAR(p.radius[k], bounding_radius(sk), 1e-15);
    EXPECT_NEAR(1.0 / p.inv_inertia[k], inertia_z(sk, 7800), 1e-12 / p.inv_inertia[k]);
    c2 += std::cos(2.0 * p.theta[k]) / p.size();
    s2 += std::sin(2.0 * p.theta[k]) / p.size();
    for (std::size_t j = 0; j < k; ++j) {
      const SuperEllipse sj{(*p.semi_a())[j], (*p.semi_b())[j], (*p.exponent())[j]};
      const SuperPairContact c =
          contact_pair(sk, {p.pos[k], p.theta[k]}, sj, {p.pos[j], p.theta[j]});
      ASSERT_LT(c.delta, 0.0) << "ids " << j << ", " << k;
    }
    for (int w = 0; w < static_cast<int>(walls.elements().size()); ++w) {
      const WallElement& el = walls.elements()[w];
      const SuperWallContact c =
          el.kind == WallKind::kCircle
              ? contact_inside_circle(sk, p.pos[k], p.theta[k], walls.circle_center(el), el.radius)
              : contact_segment(sk, p.pos[k], p.theta[k], el.a, el.b);
      ASSERT_LT(c.contact.g.delta, 0.0) << "id " << k << " wall " << w;
    }
  }
  EXPECT_EQ(fill0, 150);
  // Random angles: the mean of the doubled angle's unit vector is O(1 / sqrt(210)).
  EXPECT_LT(std::hypot(c2, s2), 0.2);
}

TEST(Fill, FillFractionPolydisperseFullRegion) {
  Scene s = drum_scene(12);
  FillSpec f = fill(0, 0.01, 0.03, FillRegion::kFull);
  f.fill_fraction = 0.2;
  s.fills.push_back(f);
  Walls walls(s);
  ParticleStore p;
  place_particles(s, walls, p);
  double area = 0.0, r_lo = 1.0, r_hi = 0.0, y_mean = 0.0;
  for (std::size_t k = 0; k < p.size(); ++k) {
    area += std::numbers::pi * p.radius[k] * p.radius[k];
    r_lo = std::min(r_lo, p.radius[k]);
    r_hi = std::max(r_hi, p.radius[k]);
    y_mean += p.pos[k].y / p.size();
  }
  const double target = 0.2 * std::numbers::pi;
  // The last particle tips the area over the target: within one largest particle.
  EXPECT_GE(area, target);
  EXPECT_LT(area - target, std::numbers::pi * 0.03 * 0.03);
  EXPECT_EQ(static_cast<std::int64_t>(p.size()), fill_count(s, 0));
  EXPECT_GE(r_lo, 0.01);
  EXPECT_LE(r_hi, 0.03);
  EXPECT_GT(r_hi - r_lo, 0.015);   // radii really are spread over the range
  EXPECT_NEAR(y_mean, 0.0, 0.15);  // "full": spread over the whole drum, not at the bottom
  expect_valid_packing(s, p, walls);
}

TEST(Fill, AnnulusTakesTheSitesNearestTheShell) {
  Scene s = drum_scene();
  s.fills.push_back(fill(100, 0.02, 0.02, FillRegion::kAnnulus));
  Walls walls(s);
  ParticleStore p;
  place_particles(s, walls, p);
  ASSERT_EQ(p.size(), 100u);
  for (std::size_t k = 0; k < p.size(); ++k) EXPECT_GT(norm(p.pos[k]), 0.85);
  expect_valid_packing(s, p, walls);
}

TEST(Fill, BoxRegionWithoutDrumAvoidsExplicitParticlesAndWalls) {
  Scene s;
  s.deck_path = "test.in";
  s.materials.push_back(steel());
  s.particles.push_back(testing_support::ball("steel", 0.2, {0.5, 0.5}));
  s.walls.push_back(testing_support::segment({0.0, 0.3}, {1.0, 0.3}, "steel"));
  FillSpec f = fill(60, 0.02, 0.04, FillRegion::kBox);
  f.box_min = {0.0, 0.0};
  f.box_max = {1.0, 1.0};
  s.fills.push_back(f);
  Walls walls(s);
  ParticleStore p;
  place_particles(s, walls, p);
  ASSERT_EQ(p.size(), 61u);
  EXPECT_DOUBLE_EQ(p.radius[0], 0.2);  // explicit particles come first, with id 0
  for (std::size_t k = 1; k < p.size(); ++k) {
    EXPECT_GE(p.pos[k].x - p.radius[k], -1e-12);
    EXPECT_LE(p.pos[k].y + p.radius[k], 1.0 + 1e-12);
  }
  expect_valid_packing(s, p, walls);
}

TEST(Fill, SameSeedSamePackingOtherSeedOtherPacking) {
  Scene s = drum_scene();
  s.fills.push_back(fill(150, 0.01, 0.03, FillRegion::kFull));
  Walls walls(s);
  ParticleStore a, b, c;
  place_particles(s, walls, a);
  place_particles(s, walls, b);
  s.run.seed = 2;
  place_particles(s, walls, c);
  int differ = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a.pos[k], b.pos[k]);
    EXPECT_EQ(a.radius[k], b.radius[k]);
    differ += !(a.pos[k] == c.pos[k]);
  }
  EXPECT_GT(differ, 140);
}

TEST(Fill, TooManyParticlesIsAnInputErrorNamingTheDeckLine) {
  Scene s = drum_scene();
  s.fills.push_back(fill(5000, 0.05, 0.05, FillRegion::kBottom));
  Walls walls(s);
  ParticleStore p;
  try {
    place_particles(s, walls, p);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("test.in:7: error: fill[0]: 5000 particles do not fit"),
              std::string::npos)
        << e.what();
  }
}

TEST(Fill, DrumRegionWithoutDrumIsAnInputError) {
  Scene s;
  s.deck_path = "test.in";
  s.materials.push_back(steel());
  s.fills.push_back(fill(10, 0.05, 0.05, FillRegion::kBottom));
  Walls walls(s);
  ParticleStore p;
  EXPECT_THROW(place_particles(s, walls, p), InputError);
}

TEST(Fill, LiftersAreAvoided) {
  Scene s = drum_scene();
  LifterSpec l;
  l.count = 8;
  l.height = 0.15;
  l.width = 0.08;
  s.drum.lifters.push_back(l);
  s.fills.push_back(fill(300, 0.02, 0.02, FillRegion::kAnnulus));
  Walls walls(s);
  ParticleStore p;
  place_particles(s, walls, p);
  ASSERT_EQ(walls.elements().size(), 1u + 8u * 3u);
  expect_valid_packing(s, p, walls);
}

// [[interaction]]: a listed pair takes its own coefficients; unlisted ones the mean.
TEST(PairCoefficients, InteractionOverridesTheMeanCoefficientByCoefficient) {
  Scene s;
  MaterialSpec a = steel("a"), b = steel("b"), c = steel("c");
  a.sliding_friction = 0.2;
  b.sliding_friction = 0.6;
  c.sliding_friction = 0.4;
  a.rolling_friction = 0.02;
  b.rolling_friction = 0.06;
  s.materials = {a, b, c};
  InteractionSpec in;
  in.material_a = "b";
  in.material_b = "a";
  in.sliding_friction = 0.9;
  in.restitution = 0.3;
  s.interactions.push_back(in);
  const PairTable t(s);
  EXPECT_DOUBLE_EQ(t(0, 1).mu_s, 0.9);
  EXPECT_DOUBLE_EQ(t(1, 0).mu_s, 0.9);
  EXPECT_DOUBLE_EQ(t(0, 1).restitution, 0.3);
  EXPECT_DOUBLE_EQ(t(0, 1).mu_r, 0.04);  // not listed: the mean
  EXPECT_DOUBLE_EQ(t(0, 2).mu_s, 0.3);   // pair not listed: the mean
  EXPECT_DOUBLE_EQ(t(1, 2).mu_s, 0.5);
  EXPECT_DOUBLE_EQ(t(2, 2).mu_s, 0.4);
  // The damping maps the pair's restitution (0.3), not the materials' (0.5).
  EXPECT_NEAR(
      restitution_hertz_clamped(-HertzMindlin::coeffs(t(0, 1)).damp / (2.0 * std::sqrt(5.0 / 6.0))),
      0.3, 1e-6);
}

}  // namespace
}  // namespace dem2d
