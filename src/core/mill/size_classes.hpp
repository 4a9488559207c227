// Size distributions by mass (docs/models.md, "Grinding: what an engineer reads"): masses in
// classes of diameter 1 um x 2^(k/4) (a quarter-octave series, the screens' sqrt(2) series
// halved), from below 1 um to above 10 m. The masses are kept as integers of 2^-40 kg, so sums
// over ranks and over a run are exact and the same on any rank count; each class also keeps the
// smallest and largest size put in it, so that a passing size is read between the sizes
// present (a product below the aperture has its P80 below the aperture).
#pragma once

#include <array>
#include <cstdint>
#include <span>

namespace dem2d {

class SizeMasses {
 public:
  static constexpr int kEdges = 95;  // 1e-6 m x 2^(k/4), k = 0 .. 94 (1e-6 .. 11.3 m)
  static constexpr int kClasses = kEdges + 1;
  static constexpr double kUnit = 0x1p-40;  // kg

  // Upper edge of class k (m); infinity for the last class.
  static double edge(int k);
  // The class of a diameter: edge(k - 1) <= d < edge(k).
  static int size_class(double diameter);
  static std::int64_t units(double kg);

  void add(double diameter, double kg);
  // The fines of a break, `kg` in all: `law_kg` of it spread below `top` (m) with the passing
  // law_kg (x / top)^alpha, the rest (what the progeny's classes left over) just below `top`.
  void add_fines(double kg, double law_kg, double top, double alpha);
  void add(const SizeMasses& other);

  std::span<std::int64_t> units() { return units_; }
  // The smallest and the largest size put in each class (m; +inf and -inf where none): summed
  // over ranks as the minimum and the maximum. low() holds the negated smallest sizes, so that
  // both combine as a maximum.
  std::span<double> neg_low() { return neg_low_; }
  std::span<double> high() { return high_; }
  std::span<const double> neg_low() const { return neg_low_; }
  std::span<const double> high() const { return high_; }
  std::span<const std::int64_t> units() const { return units_; }
  double kg(int size_class) const { return units_[static_cast<std::size_t>(size_class)] * kUnit; }
  double total_kg() const;
  bool empty() const;
  // Percent of the mass below edge(k).
  double passing(int k) const;
  // The mass below diameter d (kg), the class holding d split linearly in log(size).
  double mass_below(double d) const;
  // The size that `percent` of the mass passes, interpolated linearly in log(size) between the
  // class edges (as a sieve analysis is read); NaN when empty.
  double passing_size(double percent) const;

 private:
  void seen(int size_class, double lo, double hi);
  std::array<std::int64_t, kClasses> units_{};
  std::array<double, kClasses> neg_low_ = filled(-kInf), high_ = filled(-kInf);
  static constexpr double kInf = __builtin_huge_val();
  static constexpr std::array<double, kClasses> filled(double x) {
    std::array<double, kClasses> a{};
    for (double& v : a) v = x;
    return a;
  }
};

}  // namespace dem2d
