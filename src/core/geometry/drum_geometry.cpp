#include "core/geometry/drum_geometry.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <numbers>

namespace dem2d {

DrumGeometry::DrumGeometry(const DrumSpec& drum) : drum_(drum) {
  if (!drum.present) return;
  inner_ = drum.sides == 0 ? drum.radius : drum.radius * std::cos(std::numbers::pi / drum.sides);
  if (drum.sides >= 3) {
    const double step = 2.0 * std::numbers::pi / drum.sides;
    for (int k = 0; k < drum.sides; ++k) {
      const double phi = drum.angle + (k + 0.5) * step;  // the outward normal of side k
      side_normals_.push_back({std::cos(phi), std::sin(phi)});
    }
  }
  for (std::size_t l = 0; l < drum.lifters.size(); ++l) {
    const LifterSpec& lifter = drum.lifters[l];
    tallest_ = std::max(tallest_, lifter.height);
    // The feet on the circle of the drum's radius, half a width to each side of the radial.
    const double foot = std::sqrt(drum.radius * drum.radius - 0.25 * lifter.width * lifter.width);
    first_bar_.push_back(bars_.size());
    for (int k = 0; k < lifter.count; ++k) {
      Bar b;
      b.lifter = l;
      b.index = k;
      b.phi = lifter.angle + 2.0 * std::numbers::pi * k / lifter.count;
      b.top = inner_ - lifter.height;
      b.half_width = 0.5 * lifter.width;
      const double phi_at_start = drum.angle + b.phi;
      b.radial_at_start = {std::cos(phi_at_start), std::sin(phi_at_start)};
      const Vec2 radial{std::cos(b.phi), std::sin(b.phi)};
      const Vec2 side = perp(radial);
      b.corner = {foot * radial - b.half_width * side, b.top * radial - b.half_width * side,
                  b.top * radial + b.half_width * side, foot * radial + b.half_width * side};
      bars_.push_back(b);
    }
  }
}

Vec2 DrumGeometry::vertex(int k) const {
  const double step = 2.0 * std::numbers::pi / drum_.sides;
  return {drum_.radius * std::cos(k * step), drum_.radius * std::sin(k * step)};
}

double DrumGeometry::shell_clearance(Vec2 x) const {
  const Vec2 rel = x - drum_.center;
  double clearance = drum_.radius - norm(rel);
  for (const Vec2 normal : side_normals_)
    clearance = std::min(clearance, inner_ - dot(rel, normal));
  return clearance;
}

// Each bar as a rectangle from its top face to the drum's radius, in the lab frame at the drum's
// initial angle; sets whose top faces all lie beyond the disc's reach are skipped.
std::optional<LifterOverlap> DrumGeometry::bar_overlap(Vec2 x, double r) const {
  if (!drum_.present) return std::nullopt;
  const Vec2 rel = x - drum_.center;
  const double distance = norm(rel);
  for (const Bar& b : bars_) {
    if (distance + r <= b.top) continue;  // nearer the axis than the bar
    const Vec2 radial = b.radial_at_start;
    const double s = dot(rel, radial);        // along the bar, from the axis
    const double t = dot(rel, perp(radial));  // across it
    const double dx = std::max({b.top - s, s - drum_.radius, 0.0});
    const double dy = std::max(std::abs(t) - b.half_width, 0.0);
    const bool inside = dx == 0.0 && dy == 0.0;
    if (inside || dx * dx + dy * dy < r * r)
      return LifterOverlap{b.lifter, b.index, inside, std::sqrt(dx * dx + dy * dy)};
  }
  return std::nullopt;
}

namespace {

// The interval that a bar's corners cover along `axis`.
std::pair<double, double> extent(const DrumGeometry::Bar& bar, Vec2 axis) {
  double lo = HUGE_VAL, hi = -HUGE_VAL;
  for (const Vec2 c : bar.corner) {
    lo = std::min(lo, dot(c, axis));
    hi = std::max(hi, dot(c, axis));
  }
  return {lo, hi};
}

}  // namespace

// Separating axes: the sides of either rectangle. Bars that touch (up to rounding) are apart.
bool DrumGeometry::bars_overlap(const Bar& a, const Bar& b) {
  const double slack = 1e-12 * (norm(a.corner[0]) + norm(b.corner[0]));
  for (const Bar* bar : {&a, &b}) {
    const Vec2 radial{std::cos(bar->phi), std::sin(bar->phi)};
    for (const Vec2 axis : {radial, perp(radial)}) {
      const auto [a_lo, a_hi] = extent(a, axis);
      const auto [b_lo, b_hi] = extent(b, axis);
      if (a_hi <= b_lo + slack || b_hi <= a_lo + slack) return false;
    }
  }
  return true;
}

int DrumGeometry::bars_that_fit(std::size_t lifter) const {
  const LifterSpec& l = drum_.lifters[lifter];
  const double top = inner_ - l.height;
  if (!(top > 0.0)) return 1;  // the bars reach the axis: any two meet there
  const double span = 2.0 * std::atan(0.5 * l.width / top);
  const double fit = std::floor(2.0 * std::numbers::pi / span);  // bars 2 pi / n >= span apart
  return static_cast<int>(std::clamp(fit, 1.0, double{INT_MAX}));
}

std::optional<std::pair<std::size_t, std::size_t>> DrumGeometry::overlapping_sets() const {
  for (std::size_t m = 1; m < drum_.lifters.size(); ++m) {
    for (std::size_t l = 0; l < m; ++l) {
      if (const auto pair = overlap_between(l, m)) return pair;
    }
  }
  return std::nullopt;
}

std::optional<std::pair<std::size_t, std::size_t>> DrumGeometry::overlap_between(
    std::size_t l, std::size_t m) const {
  const long n = drum_.lifters[l].count;
  if (n <= 0) return std::nullopt;
  const double spacing = 2.0 * std::numbers::pi / static_cast<double>(n);
  const std::size_t end = first_bar_[m] + static_cast<std::size_t>(drum_.lifters[m].count);
  for (std::size_t j = first_bar_[m]; j < end; ++j) {
    const auto below =
        static_cast<long>(std::floor((bars_[j].phi - drum_.lifters[l].angle) / spacing));
    for (const long k : {below, below + 1}) {
      const std::size_t i = first_bar_[l] + static_cast<std::size_t>(((k % n) + n) % n);
      if (bars_overlap(bars_[i], bars_[j])) return std::pair{i, j};
    }
  }
  return std::nullopt;
}

}  // namespace dem2d
