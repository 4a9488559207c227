// The drum's geometry, written once: its shell (an exact circle, or a regular N-gon with its
// vertices on the circle of the drum's radius) and its lifter bars, in the drum frame (the frame
// that turns with the drum; at t = 0 it is turned by drum.angle from the lab). The walls build
// their elements from it, the fill keeps its lattice inside it, the placement checks measure
// particles against it, and the mill analytics and the feed take its radii (docs/models.md,
// "Walls").
//
// A lifter bar is a rectangle of the lifter's width standing on the shell, radial, its top face
// `height` from the shell's inner surface at its foot (the circle, or the polygon's inscribed
// circle). Its feet reach the circle of the drum's radius, so no gap is left at the base; its
// three exposed sides are wall elements.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "core/base/scene.hpp"
#include "core/base/vec2.hpp"

namespace dem2d {

// A disc that reaches into a lifter bar at t = 0: which [[drum.lifter]] and which of its bars,
// whether its centre lies inside the bar, and how far the centre is from the bar (0 inside).
struct LifterOverlap {
  std::size_t lifter = 0;
  int bar = 0;
  bool inside = false;
  double distance = 0.0;  // m
};

class DrumGeometry {
 public:
  // One lifter bar in the drum frame, relative to the drum's centre.
  struct Bar {
    std::size_t lifter = 0;  // its [[drum.lifter]] set
    int index = 0;           // its bar in the set
    double phi = 0.0;        // the bar's radial direction, rad, in the drum frame
    double top = 0.0;        // the top face's distance from the centre
    double half_width = 0.0;
    Vec2 radial_at_start{};  // (cos, sin) of drum.angle + phi: the bar's direction at t = 0
    // The exposed outline: foot, top corner, top corner, foot (the three sides p0-p1, p1-p2,
    // p2-p3 are wall elements).
    std::array<Vec2, 4> corner{};
  };

  explicit DrumGeometry(const DrumSpec& drum);

  bool present() const { return drum_.present; }
  Vec2 center() const { return drum_.center; }
  // The circle, or the polygon's circumscribed circle (its vertices lie on it).
  double radius() const { return drum_.radius; }
  // The circle, or the polygon's inscribed circle (its apothem): where a particle rests.
  double inner_radius() const { return inner_; }
  int sides() const { return drum_.sides; }
  // Vertex k of the polygon in the drum frame, at angle 2 pi k / N.
  Vec2 vertex(int k) const;
  const std::vector<Bar>& bars() const { return bars_; }
  // The tallest lifter's height (0 without lifters), and the radius clear of shell and bars.
  double tallest_lifter() const { return tallest_; }
  double clear_radius() const { return inner_ - tallest_; }

  // How far x (lab frame, the drum at its initial angle) lies inside the shell: from the
  // circle, or from the nearest side of the polygon; negative outside.
  double shell_clearance(Vec2 x) const;
  // The first lifter bar that a disc at x (lab frame, the drum at its initial angle) of radius
  // r overlaps (closer to the bar than r, or inside it), or nullopt.
  std::optional<LifterOverlap> bar_overlap(Vec2 x, double r) const;

  // Whether two bars overlap: their rectangles, from the feet to the top faces, share more than
  // an edge (bars that only touch do not overlap).
  static bool bars_overlap(const Bar& a, const Bar& b);
  // The most bars of lifter set `lifter`'s width and height that stand around the shell, evenly
  // spaced, without overlapping: a bar spans 2 atan(half width / top) seen from the centre, at
  // its top corners, and n bars are 2 pi / n apart.
  int bars_that_fit(std::size_t lifter) const;
  // Two bars of different lifter sets that overlap, as indices into bars(), or nullopt.
  std::optional<std::pair<std::size_t, std::size_t>> overlapping_sets() const;

 private:
  DrumSpec drum_;
  double inner_ = 0.0, tallest_ = 0.0;
  std::vector<Vec2> side_normals_;  // the polygon's outward side normals at t = 0
  // A bar of set m that overlaps one of set l (each bar of m against the bars of l nearest to it
  // on either side), as indices into bars_.
  std::optional<std::pair<std::size_t, std::size_t>> overlap_between(std::size_t l,
                                                                     std::size_t m) const;

  std::vector<Bar> bars_;
  std::vector<std::size_t> first_bar_;  // per lifter set, its first bar in bars_
};

}  // namespace dem2d
