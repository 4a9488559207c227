// A superellipse given by its size and form, as a fill gives it: the volume-equivalent radius r
// (the sphere of the same mass: core/shape/superellipse.hpp's superellipsoid), the aspect b / a
// and the exponent n.
#pragma once

#include <cmath>
#include <numbers>

#include "core/shape/superellipse.hpp"

namespace dem2d {

// The superellipse of volume-equivalent radius r, aspect b / a in (0, 1] and exponent n, its
// long semi-axis a along the body's x. Its volume 8 a b c K(n) (c = b) scales as a^3.
inline SuperEllipse superellipse_of_size(double r, double aspect, double n) {
  const double unit = volume(SuperEllipse{1.0, aspect, n});
  const double a = r * std::cbrt(4.0 / 3.0 * std::numbers::pi / unit);
  return {a, aspect * a, n};
}

// Its bounding radius over r (>= 1): the radius of the circle that holds a body of
// volume-equivalent radius 1.
inline double bounding_factor(double aspect, double n) {
  return bounding_radius(superellipse_of_size(1.0, aspect, n));
}

}  // namespace dem2d
