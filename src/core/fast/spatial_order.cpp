#include "core/fast/spatial_order.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dem2d {

// The classic iterative mapping: at each level, the quadrant's index, then the cell rotated
// into the quadrant's frame.
std::uint64_t hilbert_index(std::uint32_t x, std::uint32_t y, int bits) {
  std::uint64_t d = 0;
  for (std::uint32_t s = std::uint32_t{1} << (bits - 1); s > 0; s >>= 1) {
    const std::uint32_t rx = (x & s) ? 1 : 0, ry = (y & s) ? 1 : 0;
    d += static_cast<std::uint64_t>(s) * s * ((3 * rx) ^ ry);
    if (ry == 0) {
      if (rx == 1) {
        x = s - 1 - (x & (s - 1)) + (x & ~(s - 1));
        y = s - 1 - (y & (s - 1)) + (y & ~(s - 1));
      }
      std::swap(x, y);
    }
  }
  return d;
}

std::vector<std::size_t> hilbert_order(const ParticleStore& p, double cell) {
  const std::size_t n = p.n_owned();
  Vec2 lo{std::numeric_limits<double>::max(), std::numeric_limits<double>::max()};
  Vec2 hi{-lo.x, -lo.y};
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(p.pos[k].x) || !std::isfinite(p.pos[k].y)) continue;
    lo = {std::min(lo.x, p.pos[k].x), std::min(lo.y, p.pos[k].y)};
    hi = {std::max(hi.x, p.pos[k].x), std::max(hi.y, p.pos[k].y)};
  }
  const double span = std::max(hi.x - lo.x, hi.y - lo.y);
  int bits = 1;
  while (bits < 24 && std::ldexp(cell, bits) <= span) ++bits;
  const double inv = 1.0 / cell;
  const auto side = static_cast<double>((std::uint32_t{1} << bits) - 1);
  const auto coordinate = [&](double v, double v0) {
    const double c = (v - v0) * inv;  // a non-finite position goes to cell 0
    return static_cast<std::uint32_t>(std::isfinite(c) ? std::clamp(c, 0.0, side) : 0.0);
  };
  struct Key {
    std::uint64_t curve;
    std::int64_t id;
    std::size_t index;
  };
  std::vector<Key> keys(n);
  for (std::size_t k = 0; k < n; ++k)
    keys[k] = {hilbert_index(coordinate(p.pos[k].x, lo.x), coordinate(p.pos[k].y, lo.y), bits),
               p.id[k], k};
  std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
    return a.curve < b.curve || (a.curve == b.curve && a.id < b.id);
  });
  std::vector<std::size_t> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = keys[k].index;
  return order;
}

bool SortPolicy::due(std::size_t n_owned) const {
  switch (mode_) {
    case SpatialSort::kNever:
      return false;
    case SpatialSort::kAlways:
      return n_owned > 1;
    case SpatialSort::kAuto:
      break;
  }
  return n_owned >= kMinParticles && far_ > kFarFraction;
}

void SortPolicy::built(double far_fraction, bool sorted_now) {
  far_ = far_fraction;
  sorts_ += sorted_now ? 1 : 0;
}

}  // namespace dem2d
