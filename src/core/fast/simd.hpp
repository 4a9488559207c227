// Arithmetic that reads the same for one contact (double) and for a pack of contacts
// (Pack = std::experimental::native_simd<double>: 4 doubles with AVX2). The contact laws are
// written once against these helpers: selects instead of branches, so the scalar and the SIMD
// instantiation perform the same IEEE operations and give the same bits (with floating-point
// contraction off).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "core/fast/intrinsics.hpp"
// The same warning as in core/fast/intrinsics.hpp, from the simd header's lines.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <experimental/simd>
#pragma GCC diagnostic pop

namespace dem2d {

namespace stdx = std::experimental;
using Pack = stdx::native_simd<double>;
using PackMask = Pack::mask_type;
inline constexpr int kPackSize = static_cast<int>(Pack::size());

// A sum over the contacts of a pair loop in eight lanes, whatever the build's vector width:
// contact c of a batch into lane c mod 8, the lanes then added in one fixed order (the order in
// which stdx::reduce adds a pack of 8). So a rank's energies are the same bits in a build with
// 8-wide vectors (AVX-512) and in one with 4 (AVX2) or 2 (SSE2), as its particles are.
class EightLanes {
 public:
  static constexpr std::size_t kGroups = 8 / kPackSize;
  static_assert(kGroups * kPackSize == 8, "a pack of 1, 2, 4 or 8 doubles");
  // The pack of contacts [c, c + kPackSize) (c a multiple of kPackSize).
  [[gnu::always_inline]] void add(std::size_t c, const Pack& v) {
    lanes_[(c / kPackSize) % kGroups] += v;
  }
  double sum() const {
    double l[8];
    for (std::size_t g = 0; g < kGroups; ++g)
      lanes_[g].copy_to(l + g * kPackSize, stdx::element_aligned);
    return ((l[0] + l[4]) + (l[2] + l[6])) + ((l[1] + l[5]) + (l[3] + l[7]));
  }

 private:
  std::array<Pack, kGroups> lanes_ = make_zero();
  static std::array<Pack, kGroups> make_zero() {
    std::array<Pack, kGroups> z;
    z.fill(Pack(0.0));
    return z;
  }
};

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
