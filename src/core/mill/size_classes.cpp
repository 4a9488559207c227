#include "core/mill/size_classes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dem2d {

double SizeMasses::edge(int k) {
  if (k >= kEdges) return std::numeric_limits<double>::infinity();
  return 1e-6 * std::exp2(0.25 * k);
}

int SizeMasses::size_class(double diameter) {
  if (!(diameter >= edge(0))) return 0;
  int k = std::clamp(static_cast<int>(std::floor(4.0 * std::log2(diameter / 1e-6))) + 1, 1, kEdges);
  // The floating log may land one class off next to an edge: the edges decide.
  while (k > 1 && diameter < edge(k - 1)) --k;
  while (k < kEdges && diameter >= edge(k)) ++k;
  return k;
}

std::int64_t SizeMasses::units(double kg) { return std::llround(kg / kUnit); }

void SizeMasses::add(double diameter, double kg) {
  const int k = size_class(diameter);
  units_[static_cast<std::size_t>(k)] += units(kg);
  seen(k, diameter, diameter);
}

void SizeMasses::seen(int k, double lo, double hi) {
  const auto c = static_cast<std::size_t>(k);
  neg_low_[c] = std::max(neg_low_[c], -lo);
  high_[c] = std::max(high_[c], hi);
}

void SizeMasses::add_fines(double kg, double law_kg, double top, double alpha) {
  // Below top the law passes law_kg (x / top)^alpha; each class below top_class takes its part,
  // top_class the rest, so that the classes add up to `kg` exactly.
  const int top_class = size_class(std::nextafter(top, 0.0));
  std::int64_t spread = 0;
  for (int k = top_class - 1; k >= 0 && law_kg > 0.0; --k) {
    const double hi = std::pow(edge(k) / top, alpha);
    const double lo = k > 0 ? std::pow(edge(k - 1) / top, alpha) : 0.0;
    const std::int64_t u = units(law_kg * (hi - lo));
    units_[static_cast<std::size_t>(k)] += u;
    spread += u;
    if (u != 0) seen(k, k > 0 ? edge(k - 1) : 0.0, edge(k));
    if (hi < 1e-15) break;
  }
  units_[static_cast<std::size_t>(top_class)] += units(kg) - spread;
  seen(top_class, top_class > 0 ? edge(top_class - 1) : 0.0, top);
}

void SizeMasses::add(const SizeMasses& other) {
  for (std::size_t k = 0; k < units_.size(); ++k) {
    units_[k] += other.units_[k];
    neg_low_[k] = std::max(neg_low_[k], other.neg_low_[k]);
    high_[k] = std::max(high_[k], other.high_[k]);
  }
}

double SizeMasses::total_kg() const {
  std::int64_t s = 0;
  for (const std::int64_t u : units_) s += u;
  return s * kUnit;
}

bool SizeMasses::empty() const {
  return std::all_of(units_.begin(), units_.end(), [](std::int64_t u) { return u == 0; });
}

double SizeMasses::passing(int k) const {
  std::int64_t below = 0, all = 0;
  for (int j = 0; j < kClasses; ++j) {
    all += units_[static_cast<std::size_t>(j)];
    if (j <= k) below += units_[static_cast<std::size_t>(j)];
  }
  return all > 0 ? 100.0 * static_cast<double>(below) / static_cast<double>(all)
                 : std::numeric_limits<double>::quiet_NaN();
}

double SizeMasses::mass_below(double d) const {
  const int c = size_class(d);
  std::int64_t below = 0;
  for (int k = 0; k < c; ++k) below += units_[static_cast<std::size_t>(k)];
  // Within class c, between the smallest and the largest size put in it.
  const auto u = static_cast<double>(units_[static_cast<std::size_t>(c)]);
  const double lo = -neg_low_[static_cast<std::size_t>(c)], hi = high_[static_cast<std::size_t>(c)];
  double part = 0.0;
  if (u > 0.0) {
    if (d > hi) {
      part = u;
    } else if (d > lo) {
      part = lo > 0.0 ? u * std::log(d / lo) / std::log(hi / lo) : u * d / hi;
    }
  }
  return (static_cast<double>(below) + part) * kUnit;
}

double SizeMasses::passing_size(double percent) const {
  std::int64_t all = 0;
  for (const std::int64_t u : units_) all += u;
  if (all == 0) return std::numeric_limits<double>::quiet_NaN();
  const double target = percent / 100.0 * static_cast<double>(all);
  std::int64_t below = 0;
  for (int k = 0; k < kClasses; ++k) {
    const std::int64_t next = below + units_[static_cast<std::size_t>(k)];
    if (static_cast<double>(next) >= target && units_[static_cast<std::size_t>(k)] > 0) {
      // Within class k, between the smallest and the largest size put in it, linear in log.
      const double f = (target - static_cast<double>(below)) /
                       static_cast<double>(units_[static_cast<std::size_t>(k)]);
      const double lo = -neg_low_[static_cast<std::size_t>(k)],
                   hi = high_[static_cast<std::size_t>(k)];
      if (!(lo > 0.0)) return f * hi;
      return lo * std::pow(hi / lo, f);
    }
    below = next;
  }
  return edge(kEdges - 1);
}

}  // namespace dem2d
