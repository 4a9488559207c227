// The sizes of the particles a [[fill]] places (docs/input.md, "Size distributions"):
//   - uniform: radii uniform in [radius_min, radius_max] (one radius when they are equal);
//   - normal, lognormal: diameters by mass, the law a sieve analysis gives, truncated to
//     [2 radius_min, 2 radius_max]. A particle's diameter is drawn by number from the number
//     density f_M(d) / d^3 (a sphere's mass goes as d^3), tabulated in kLawSteps equal steps;
//   - table: a few sizes with their mass fractions, whole particles apportioned to the sizes
//     (largest remainders) and shuffled over the fill.
// Every draw is keyed by (run.seed, fill, particle), so every rank gets the same radii.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/base/scene.hpp"

namespace dem2d {

// The random streams of the fills: a fill's radii at kFillStream + fill, its lattice's keys,
// jitter, size-table shuffle and mixing at the offsets of fill.cpp.
inline constexpr std::uint64_t kFillStream = 0xF111ULL << 32;

// Steps of the tabulated number density of a normal or lognormal fill.
inline constexpr int kLawSteps = 4096;

// The cross-sections sum pi r^2 a fill by fill_fraction or bed_filling places at least
// (fill_fraction pi R^2, or bed_filling kBedPacking pi R^2); 0 for a fill by count.
double fill_target_area(const Scene& scene, const FillSpec& s);

// The radius of the circle that holds the fill's largest particle: radius_max for discs, the
// bounding radius of a superellipse of volume-equivalent radius radius_max (its lattice's
// spacing is 2.1 times this).
double placement_radius_max(const FillSpec& s);

// The radii of fill `fill`'s particles in the order of their ids: its count, or as many as
// reach its target area (the table: the count that mean area gives, see table_counts).
std::vector<double> fill_radii(const Scene& scene, std::size_t fill);

// pi E[r^2] by number over the fill's law, for estimates without drawing the radii.
double mean_particle_area(const FillSpec& s);

// The share of each table size in number: (w_i / d_i^3) / sum_j (w_j / d_j^3).
std::vector<double> table_number_fractions(const FillSpec& s);

// Whole particles per table size for n in all: n times its number fraction rounded down, the
// particles left over one each to the sizes with the largest remainders (the smaller size
// first on a tie), so each size is within one particle of its exact share.
std::vector<std::int64_t> table_counts(const FillSpec& s, std::int64_t n);

// A normal or lognormal fill's diameters by number: the density f_M(d) / d^3 at kLawSteps + 1
// equal steps over [2 radius_min, 2 radius_max], its cumulative sum by trapezoids, inverted
// with linear interpolation within a step.
class DiameterLaw {
 public:
  explicit DiameterLaw(const FillSpec& s);
  // The diameter at u in [0, 1): the inverse of the cumulative number distribution.
  double diameter(double u) const;
  // pi E[d^2 / 4] by number.
  double mean_area() const { return mean_area_; }

 private:
  double lo_ = 0.0, step_ = 0.0, mean_area_ = 0.0;
  std::vector<double> cdf_;  // at the nodes, not normalised
};

}  // namespace dem2d
