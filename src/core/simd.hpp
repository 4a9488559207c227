// Arithmetic that reads the same for one contact (double) and for a pack of contacts
// (Pack = std::experimental::native_simd<double>: 4 doubles with AVX2). The contact laws are
// written once against these helpers: selects instead of branches, so the scalar and the SIMD
// instantiation perform the same IEEE operations and give the same bits (with floating-point
// contraction off).
#pragma once

#include <algorithm>
#include <cmath>

#include "core/intrinsics.hpp"
// The same warning as in core/intrinsics.hpp, from the simd header's lines.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <experimental/simd>
#pragma GCC diagnostic pop

namespace dem2d {

namespace stdx = std::experimental;
using Pack = stdx::native_simd<double>;
using PackMask = Pack::mask_type;
inline constexpr int kPackSize = static_cast<int>(Pack::size());

// Select: c ? a : b, lane by lane.
[[gnu::always_inline]] inline double select(bool c, double a, double b) { return c ? a : b; }
[[gnu::always_inline]] inline Pack select(const PackMask& c, const Pack& a, const Pack& b) {
  Pack r = b;
  stdx::where(c, r) = a;
  return r;
}
[[gnu::always_inline]] inline double vsqrt(double x) { return std::sqrt(x); }
[[gnu::always_inline]] inline Pack vsqrt(const Pack& x) { return stdx::sqrt(x); }
[[gnu::always_inline]] inline double vabs(double x) { return std::abs(x); }
[[gnu::always_inline]] inline Pack vabs(const Pack& x) { return stdx::abs(x); }
[[gnu::always_inline]] inline double vmax(double a, double b) { return std::max(a, b); }
[[gnu::always_inline]] inline Pack vmax(const Pack& a, const Pack& b) { return stdx::max(a, b); }
[[gnu::always_inline]] inline double vmin(double a, double b) { return std::min(a, b); }
[[gnu::always_inline]] inline Pack vmin(const Pack& a, const Pack& b) { return stdx::min(a, b); }
[[gnu::always_inline]] inline double vcopysign(double m, double s) { return std::copysign(m, s); }
[[gnu::always_inline]] inline Pack vcopysign(const Pack& m, const Pack& s) {
  return stdx::copysign(m, s);
}
// sign(x): -1, 0 or +1.
[[gnu::always_inline]] inline double vsign(double x) {
  return select(x > 0.0, 1.0, select(x < 0.0, -1.0, 0.0));
}
[[gnu::always_inline]] inline Pack vsign(const Pack& x) {
  return select(x > 0.0, Pack(1.0), select(x < 0.0, Pack(-1.0), Pack(0.0)));
}
[[gnu::always_inline]] inline bool any_of(bool b) { return b; }
[[gnu::always_inline]] inline bool any_of(const PackMask& m) { return stdx::any_of(m); }

}  // namespace dem2d
