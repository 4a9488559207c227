// The pair gather's mirror of the particles (core/fast/pair_gather.hpp): one 64-byte line per
// particle with what the gather reads (position, velocity, spin, radius, mass, material), so that
// a candidate's two particles are two aligned loads (AMD's gather instructions load no faster
// than scalar loads: measured 7 % against 36 % of the block's time). Only the AVX-512 gather
// uses it.
//
// Who writes it: the contact kernel before each pair loop, all particles, unless Velocity
// Verlet's drift has just written the owned lines itself (the same values, written while the
// drift holds them in registers: a separate pass re-read 60 bytes per particle, and past the
// caches that pass cost as much as the drift). The drift claims the owned lines for the current
// storage layout (expect_owned); the next fill takes the claim (fresh_lines) and writes only
// what the claim does not cover. A claim made for another layout (the store was sorted or
// particles migrated in between) covers nothing.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/base/array.hpp"
#include "core/base/vec2.hpp"

#if defined(__AVX512F__) && defined(__AVX512VL__)
#define DEM2D_VECTOR_GATHER 1
// The intrinsics alone: this header reaches code built by clang too (the fuzz build of the deck
// reader), which core/fast/simd.hpp's std::experimental::simd must not.
#include "core/fast/intrinsics.hpp"
#else
#define DEM2D_VECTOR_GATHER 0
#endif

namespace dem2d {

// One particle's line. `material` is stored as a double: the gather converts nothing.
struct alignas(64) PairKinematics {
  double x, y, vx, vy, w, r, m, material;
};

#if DEM2D_VECTOR_GATHER
// One line written as two 32-byte halves, x and v loaded from the store (the compiler's own
// stores were 3x slower; built from the drift's registers, the line cost the drift stack spills).
[[gnu::always_inline]] inline void store_kinematics(PairKinematics& out, const Vec2& x,
                                                    const Vec2& v, double w, double r, double m,
                                                    std::int32_t material) {
  const __m256d motion =
      _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(&x.x)), _mm_loadu_pd(&v.x), 1);
  _mm256_store_pd(&out.x, motion);
  _mm256_store_pd(&out.w, _mm256_setr_pd(w, r, m, static_cast<double>(material)));
}

// Four consecutive particles' lines at once (Velocity Verlet's drift, four at a time): x and v
// hold (x, y) of the four side by side, w their spins; r, m and material point at the first's.
[[gnu::always_inline]] inline void store_kinematics4(PairKinematics* out, __m512d x, __m512d v,
                                                     __m256d w, const double* r, const double* m,
                                                     const std::int32_t* material) {
  // Motion halves (x, y, vx, vy) of particles 0|1 and 2|3, body halves (w, r, m, material)
  // likewise, then each line from its two halves.
  const __m512d motion01 =
      _mm512_permutex2var_pd(x, _mm512_setr_epi64(0, 1, 8, 9, 2, 3, 10, 11), v);
  const __m512d motion23 =
      _mm512_permutex2var_pd(x, _mm512_setr_epi64(4, 5, 12, 13, 6, 7, 14, 15), v);
  const __m512d wr = _mm512_insertf64x4(_mm512_castpd256_pd512(w), _mm256_loadu_pd(r), 1);
  const __m512d mm = _mm512_insertf64x4(
      _mm512_castpd256_pd512(_mm256_loadu_pd(m)),
      _mm256_cvtepi32_pd(_mm_loadu_si128(reinterpret_cast<const __m128i*>(material))), 1);
  const __m512d body01 =
      _mm512_permutex2var_pd(wr, _mm512_setr_epi64(0, 4, 8, 12, 1, 5, 9, 13), mm);
  const __m512d body23 =
      _mm512_permutex2var_pd(wr, _mm512_setr_epi64(2, 6, 10, 14, 3, 7, 11, 15), mm);
  _mm512_store_pd(&out[0].x, _mm512_shuffle_f64x2(motion01, body01, 0x44));
  _mm512_store_pd(&out[1].x, _mm512_shuffle_f64x2(motion01, body01, 0xEE));
  _mm512_store_pd(&out[2].x, _mm512_shuffle_f64x2(motion23, body23, 0x44));
  _mm512_store_pd(&out[3].x, _mm512_shuffle_f64x2(motion23, body23, 0xEE));
}
#endif

class KinematicsMirror {
 public:
  // The lines of particles [0, n); lines kept when it grows.
  PairKinematics* lines(std::size_t n) {
    if (lines_.size() < n) lines_.resize(n);
    return lines_.data();
  }
  const PairKinematics* data() const { return lines_.data(); }
  // The drift about to run writes lines [0, n_owned) of this storage layout.
  void expect_owned(std::uint64_t layout) {
    claim_ = layout;
    claimed_ = true;
  }
  // How many leading lines hold the current state (the claim's n_owned if it was made for
  // `layout`, else 0). Uses the claim up: the next fill writes every line again.
  std::size_t fresh_lines(std::uint64_t layout, std::size_t n_owned) {
    const bool fresh = claimed_ && claim_ == layout;
    claimed_ = false;
    return fresh ? n_owned : 0;
  }

 private:
  Array<PairKinematics> lines_;
  std::uint64_t claim_ = 0;
  bool claimed_ = false;
};

}  // namespace dem2d
