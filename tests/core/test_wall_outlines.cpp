// wall_outlines(): the drum, its lifters and the [[wall]] segments as lab-frame polylines at the
// walls' current time (what snapshots.xmf draws).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/geometry/walls.hpp"

namespace dem2d {
namespace {

Scene drum(int sides, double radius = 1.25, Vec2 center = {0.5, -0.25}) {
  Scene s;
  MaterialSpec steel;
  steel.name = "steel";
  s.materials.push_back(steel);
  s.drum.present = true;
  s.drum.radius = radius;
  s.drum.center = center;
  s.drum.sides = sides;
  s.drum.speed = 1.8;
  s.drum.angle = 0.3;
  s.drum.material = "steel";
  return s;
}

LifterSpec lifters(int count) {
  LifterSpec l;
  l.count = count;
  l.height = 0.15;
  l.width = 0.08;
  l.angle = 0.1;
  return l;
}

TEST(WallOutlines, CircleIsClosedOnTheDrumRadiusAndStartsAtTheDrumAngle) {
  const Scene s = drum(0);
  Walls walls(s);
  walls.update(0.7);
  const auto lines = wall_outlines(walls, 64);
  ASSERT_EQ(lines.size(), 1u);
  const std::vector<Vec2>& circle = lines[0];
  ASSERT_EQ(circle.size(), 65u);
  EXPECT_EQ(circle.front(), circle.back());
  for (const Vec2 p : circle) EXPECT_NEAR(norm(p - s.drum.center), s.drum.radius, 1e-12);
  const Vec2 first = circle[0] - s.drum.center;
  EXPECT_NEAR(std::atan2(first.y, first.x), walls.drum_angle(), 1e-12);
  // Evenly spaced: every chord the same.
  const double chord = 2.0 * s.drum.radius * std::sin(std::numbers::pi / 64);
  for (std::size_t k = 1; k < circle.size(); ++k)
    EXPECT_NEAR(norm(circle[k] - circle[k - 1]), chord, 1e-12) << "k=" << k;
  EXPECT_EQ(wall_outlines(walls, 1)[0].size(), 4u) << "at least a triangle";
  EXPECT_EQ(wall_outlines(walls)[0].size(), 257u);
}

TEST(WallOutlines, PolygonIsItsSidesChainedAndClosedWithVerticesOnTheCircle) {
  const Scene s = drum(16);
  Walls walls(s);
  walls.update(0.4);
  const auto lines = wall_outlines(walls);
  ASSERT_EQ(lines.size(), 1u);
  const std::vector<Vec2>& polygon = lines[0];
  ASSERT_EQ(polygon.size(), 17u);
  EXPECT_EQ(polygon.front(), polygon.back());
  for (const Vec2 p : polygon) EXPECT_NEAR(norm(p - s.drum.center), s.drum.radius, 1e-12);
  // The vertices are the elements' lab-frame ends.
  for (int k = 0; k < 16; ++k) EXPECT_EQ(polygon[k], walls.elements()[k].a) << "k=" << k;
}

TEST(WallOutlines, LiftersAreFourPointPolylinesThatTurnWithTheDrumByItsAngle) {
  Scene s = drum(16);
  s.drum.lifters.push_back(lifters(6));
  Walls walls(s);
  walls.update(0.0);
  const auto before = wall_outlines(walls);
  ASSERT_EQ(before.size(), 1u + 6u);
  const double angle0 = walls.drum_angle();
  walls.update(1.3);
  const auto after = wall_outlines(walls);
  ASSERT_EQ(after.size(), before.size());
  const double turned = walls.drum_angle() - angle0;
  EXPECT_NEAR(turned, 1.8 * 1.3, 1e-12);
  for (std::size_t l = 1; l < after.size(); ++l) {
    ASSERT_EQ(after[l].size(), 4u) << "lifter " << l;
    for (std::size_t k = 0; k < 4; ++k) {
      const Vec2 expected = s.drum.center + rotate(before[l][k] - s.drum.center, turned);
      EXPECT_NEAR(after[l][k].x, expected.x, 1e-12) << "lifter " << l << " point " << k;
      EXPECT_NEAR(after[l][k].y, expected.y, 1e-12) << "lifter " << l << " point " << k;
    }
    // Both feet on (just beyond) the shell, the top the lifter's height inside it.
    const double foot = std::sqrt(1.25 * 1.25 - 0.25 * 0.08 * 0.08);
    EXPECT_NEAR(norm(after[l][0] - s.drum.center), std::hypot(foot, 0.04), 1e-12);
    EXPECT_NEAR(norm(after[l][3] - s.drum.center), std::hypot(foot, 0.04), 1e-12);
    const double inner = 1.25 * std::cos(std::numbers::pi / 16) - 0.15;
    EXPECT_NEAR(norm(after[l][1] - s.drum.center), std::hypot(inner, 0.04), 1e-12);
    EXPECT_NEAR(norm(after[l][2] - s.drum.center), std::hypot(inner, 0.04), 1e-12);
  }
}

TEST(WallOutlines, SegmentsAreTwoPointPolylinesThatTranslate) {
  Scene s;
  MaterialSpec steel;
  steel.name = "steel";
  s.materials.push_back(steel);
  WallSpec floor{{-1.0, 0.0}, {1.0, 0.0}, "steel", {0.0, 0.0}};
  WallSpec moving{{1.0, 0.0}, {1.0, 2.0}, "steel", {0.5, 0.0}};  // meets the floor's end
  s.walls = {floor, moving};
  Walls walls(s);
  walls.update(2.0);
  const auto lines = wall_outlines(walls);
  ASSERT_EQ(lines.size(), 2u) << "two bodies: never chained";
  EXPECT_EQ(lines[0], (std::vector<Vec2>{{-1.0, 0.0}, {1.0, 0.0}}));
  EXPECT_EQ(lines[1], (std::vector<Vec2>{{2.0, 0.0}, {2.0, 2.0}}));
}

TEST(WallOutlines, DrumWithLiftersAndWallsInElementOrder) {
  Scene s = drum(0);
  s.drum.lifters.push_back(lifters(3));
  s.walls.push_back({{-0.5, -0.5}, {0.5, -0.5}, "steel", {0.0, 0.0}});
  Walls walls(s);
  const auto lines = wall_outlines(walls, 32);
  ASSERT_EQ(lines.size(), 1u + 3u + 1u);
  EXPECT_EQ(lines[0].size(), 33u);
  for (std::size_t l = 1; l <= 3; ++l) EXPECT_EQ(lines[l].size(), 4u);
  EXPECT_EQ(lines[4].size(), 2u);
  EXPECT_TRUE(wall_outlines(Walls(Scene{})).empty());
}

}  // namespace
}  // namespace dem2d
