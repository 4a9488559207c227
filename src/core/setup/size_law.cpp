#include "core/setup/size_law.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "core/base/random.hpp"
#include "core/mill/mill_analytics.hpp"  // kBedPacking
#include "core/shape/superellipse_sizing.hpp"

namespace dem2d {

double placement_radius_max(const FillSpec& s) {
  if (s.shape == ParticleShape::kDisc) return s.radius_max;
  return s.radius_max * bounding_factor(s.aspect, s.exponent);
}

namespace {

// The stream of a table fill's shuffle (fill.cpp uses +1000, +2000 and +4000).
constexpr std::uint64_t kTableShuffle = kFillStream + 3000;

// The number density of diameters, not normalised: the mass density f_M(d) over d^3.
double number_density(const FillSpec& s, double d) {
  double mass = 0.0;
  if (s.size_distribution == SizeDistribution::kNormal) {
    const double z = (d - s.d50) / s.sigma;
    mass = std::exp(-0.5 * z * z);
  } else {
    const double z = std::log(d / s.d50) / std::log(s.geometric_sd);
    mass = std::exp(-0.5 * z * z) / d;
  }
  return mass / (d * d * d);
}

// A table fill's radii: its count (or the count its target area over the mean area gives)
// apportioned to the sizes, in an order shuffled by (seed, fill).
std::vector<double> table_radii(const Scene& scene, std::size_t f) {
  const FillSpec& s = scene.fills[f];
  std::int64_t n = s.count;
  if (n <= 0) {
    n = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::ceil(fill_target_area(scene, s) /
                                                                      mean_particle_area(s))));
  }
  const std::vector<std::int64_t> counts = table_counts(s, n);
  std::vector<double> radii;
  radii.reserve(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < counts.size(); ++i)
    radii.insert(radii.end(), counts[i], 0.5 * s.sizes[i]);
  for (std::size_t i = radii.size(); i > 1; --i) {  // Fisher-Yates
    const double u = random_uniform(scene.run.seed, kTableShuffle + f, i - 1);
    const auto j = std::min(static_cast<std::size_t>(u * static_cast<double>(i)), i - 1);
    std::swap(radii[i - 1], radii[j]);
  }
  return radii;
}

}  // namespace

double fill_target_area(const Scene& scene, const FillSpec& s) {
  if (s.count > 0) return 0.0;
  const double R = scene.drum.radius;
  if (s.bed_filling > 0.0) return s.bed_filling * kBedPacking * std::numbers::pi * R * R;
  return s.fill_fraction * std::numbers::pi * R * R;
}

std::vector<double> fill_radii(const Scene& scene, std::size_t f) {
  const FillSpec& s = scene.fills[f];
  if (s.size_distribution == SizeDistribution::kTable) return table_radii(scene, f);
  const bool by_law = s.size_distribution == SizeDistribution::kNormal ||
                      s.size_distribution == SizeDistribution::kLognormal;
  const DiameterLaw law = by_law ? DiameterLaw(s) : DiameterLaw(FillSpec{});
  const auto radius = [&](std::int64_t k) {
    if (!by_law && s.radius_max <= s.radius_min) return s.radius_min;
    const double u = random_uniform(scene.run.seed, kFillStream + f, static_cast<std::uint64_t>(k));
    if (by_law) return 0.5 * law.diameter(u);
    return s.radius_min + u * (s.radius_max - s.radius_min);
  };
  std::vector<double> radii;
  if (s.count > 0) {
    radii.reserve(static_cast<std::size_t>(s.count));
    for (std::int64_t k = 0; k < s.count; ++k) radii.push_back(radius(k));
    return radii;
  }
  const double target = fill_target_area(scene, s);
  double area = 0.0;
  for (std::int64_t k = 0; area < target; ++k) {
    const double r = radius(k);
    area += std::numbers::pi * r * r;
    radii.push_back(r);
  }
  return radii;
}

double mean_particle_area(const FillSpec& s) {
  switch (s.size_distribution) {
    case SizeDistribution::kNormal:
    case SizeDistribution::kLognormal:
      return DiameterLaw(s).mean_area();
    case SizeDistribution::kTable: {
      const std::vector<double> share = table_number_fractions(s);
      double area = 0.0;
      for (std::size_t i = 0; i < share.size(); ++i)
        area += share[i] * std::numbers::pi * 0.25 * s.sizes[i] * s.sizes[i];
      return area;
    }
    case SizeDistribution::kUniform:
      break;
  }
  const double a = s.radius_min, b = s.radius_max;
  return std::numbers::pi * (a * a + a * b + b * b) / 3.0;
}

std::vector<double> table_number_fractions(const FillSpec& s) {
  std::vector<double> share(s.sizes.size(), 0.0);
  double sum = 0.0;
  for (std::size_t i = 0; i < share.size() && i < s.mass_fractions.size(); ++i) {
    const double d = s.sizes[i];
    share[i] = s.mass_fractions[i] / (d * d * d);
    sum += share[i];
  }
  for (double& x : share) x = sum > 0.0 ? x / sum : 0.0;
  return share;
}

std::vector<std::int64_t> table_counts(const FillSpec& s, std::int64_t n) {
  const std::vector<double> share = table_number_fractions(s);
  std::vector<std::int64_t> counts(share.size(), 0);
  std::vector<std::pair<double, std::size_t>> remainders;
  std::int64_t left = n;
  for (std::size_t i = 0; i < share.size(); ++i) {
    const double exact = static_cast<double>(n) * share[i];
    counts[i] = static_cast<std::int64_t>(std::floor(exact));
    left -= counts[i];
    remainders.emplace_back(exact - static_cast<double>(counts[i]), i);
  }
  std::stable_sort(remainders.begin(), remainders.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (std::size_t k = 0; left > 0 && k < remainders.size(); ++k, --left)
    ++counts[remainders[k].second];
  return counts;
}

DiameterLaw::DiameterLaw(const FillSpec& s)
    : lo_(2.0 * s.radius_min), step_(2.0 * (s.radius_max - s.radius_min) / kLawSteps) {
  if (!(step_ > 0.0)) {
    mean_area_ = std::numbers::pi * 0.25 * lo_ * lo_;
    return;
  }
  cdf_.assign(kLawSteps + 1, 0.0);
  double g = number_density(s, lo_), area = 0.0;
  for (int i = 1; i <= kLawSteps; ++i) {
    const double d0 = lo_ + step_ * (i - 1), d = lo_ + step_ * i;
    const double next = number_density(s, d);
    cdf_[i] = cdf_[i - 1] + 0.5 * step_ * (g + next);
    area += 0.5 * step_ * (g * d0 * d0 + next * d * d);
    g = next;
  }
  mean_area_ = cdf_.back() > 0.0 ? std::numbers::pi * 0.25 * area / cdf_.back()
                                 : std::numbers::pi * 0.25 * lo_ * lo_;
}

double DiameterLaw::diameter(double u) const {
  if (cdf_.empty() || !(cdf_.back() > 0.0)) return lo_;
  const double t = u * cdf_.back();
  const auto above = std::upper_bound(cdf_.begin(), cdf_.end(), t);
  const auto i =
      static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(above - cdf_.begin(), 1, kLawSteps) - 1);
  const double width = cdf_[i + 1] - cdf_[i];
  const double within = width > 0.0 ? std::clamp((t - cdf_[i]) / width, 0.0, 1.0) : 0.0;
  return lo_ + step_ * (static_cast<double>(i) + within);
}

}  // namespace dem2d
