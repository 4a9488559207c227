#include "io/placement.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>

#include "io/deck_reader.hpp"
#include "io/particle_csv.hpp"

namespace dem2d::deck {

void Placement::check() {
  for (std::size_t i = 0; i < scene_.particles.size(); ++i) {
    if (in_drum(i)) clear_of_lifters(i);
  }
  check_pairs();
  for (const FileRows& file : files_) {
    if (file.reported > kMaxCsvErrors) {
      diag_.add(fmt::format("{}: error: {} more misplaced rows in this file not shown", file.shown,
                            file.reported - kMaxCsvErrors));
    }
  }
}

// Inside the drum's circle or polygon, by the particle's clearance from the nearest side: an
// overlap with the shell (radius - clearance) of at most kPlacementOverlap of the radius.
bool Placement::in_drum(std::size_t i) {
  const DrumSpec& d = scene_.drum;
  const ParticleSpec& p = scene_.particles[i];
  if (!d.present) return false;
  const double clearance = drum_.shell_clearance(p.position);
  const double overlap = p.radius - clearance;
  if (overlap <= kPlacementOverlap * p.radius) return true;
  const std::string drum =
      fmt::format("the drum (radius {:g} m about [{:g}, {:g}]{})", d.radius, d.center.x, d.center.y,
                  d.sides >= 3 ? fmt::format(", {} sides", d.sides) : std::string());
  report(i, clearance <= -p.radius
                ? fmt::format("the particle (radius {:g} m) lies outside {}; place it at least "
                              "its radius inside the shell",
                              p.radius, drum)
                : fmt::format("the particle (radius {:g} m) overlaps the shell of {} by {:.3g} "
                              "% of its radius; {}",
                              p.radius, drum, 100.0 * overlap / p.radius, allowed()));
  return false;
}

// Clear of the bars: nearer to none than its radius less kPlacementOverlap of it.
void Placement::clear_of_lifters(std::size_t i) {
  const ParticleSpec& p = scene_.particles[i];
  const double reach = p.radius - kPlacementOverlap * p.radius;
  const auto bar = drum_.bar_overlap(p.position, reach);
  if (!bar) return;
  const std::string which = fmt::format(
      "bar {} of drum.lifter[{}] (the bars at the drum's initial angle)", bar->bar, bar->lifter);
  report(i, bar->inside
                ? fmt::format("the particle (radius {:g} m) lies inside {}; place it clear of "
                              "the lifters",
                              p.radius, which)
                : fmt::format("the particle (radius {:g} m) overlaps {} by {:.3g} % of its "
                              "radius; {}",
                              p.radius, which, 100.0 * (p.radius - bar->distance) / p.radius,
                              allowed()));
}

// The tolerance, as every overlap message states it.
std::string Placement::allowed() {
  return fmt::format("at most {:g} % is allowed at the start", 100.0 * kPlacementOverlap);
}

// Pairs closer than allowed, found on a grid of cells as wide as the largest diameter, and
// reported at the later particle in deck order.
void Placement::check_pairs() {
  const std::vector<ParticleSpec>& ps = scene_.particles;
  double r_max = 0.0;
  for (const ParticleSpec& p : ps) r_max = std::max(r_max, p.radius);
  const double h = 2.0 * r_max;
  const auto cell = [h](double x) {  // clamped: a far-away particle is reported anyway
    return static_cast<std::int64_t>(std::clamp(std::floor(x / h), -1.0e9, 1.0e9));
  };
  const auto key = [](std::int64_t cx, std::int64_t cy) { return (cx << 32) ^ (cy & 0xffffffff); };
  std::unordered_map<std::int64_t, std::vector<std::size_t>> cells;
  for (std::size_t i = 0; i < ps.size(); ++i)
    cells[key(cell(ps[i].position.x), cell(ps[i].position.y))].push_back(i);
  std::vector<std::pair<std::size_t, std::size_t>> close;  // (later, earlier)
  for (std::size_t i = 0; i < ps.size(); ++i) {
    const std::int64_t cx = cell(ps[i].position.x), cy = cell(ps[i].position.y);
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        const auto it = cells.find(key(cx + dx, cy + dy));
        if (it == cells.end()) continue;
        for (const std::size_t j : it->second)
          if (j > i && overlap(i, j) > kPlacementOverlap * smaller(i, j)) close.emplace_back(j, i);
      }
  }
  std::sort(close.begin(), close.end());
  for (const auto& [j, i] : close) report_pair(i, j);
}

double Placement::overlap(std::size_t i, std::size_t j) const {
  const ParticleSpec& p = scene_.particles[i];
  const ParticleSpec& q = scene_.particles[j];
  return p.radius + q.radius - norm(q.position - p.position);
}

double Placement::smaller(std::size_t i, std::size_t j) const {
  return std::min(scene_.particles[i].radius, scene_.particles[j].radius);
}

void Placement::report_pair(std::size_t i, std::size_t j) {
  const double gap = norm(scene_.particles[j].position - scene_.particles[i].position);
  const double s = smaller(i, j);
  report(j, gap <= 1e-9 * s
                ? fmt::format("coincides with {}; give each particle its own place", name(i))
                : fmt::format("overlaps {} by {:.3g} % of the smaller radius; {}", name(i),
                              100.0 * overlap(i, j) / s, allowed()));
}

// The file whose rows hold particle i (i past the tables).
FileRows& Placement::file_of(std::size_t i) {
  auto it = std::upper_bound(files_.begin(), files_.end(), i,
                             [](std::size_t k, const FileRows& f) { return k < f.first; });
  return *(it - 1);
}

// "particle[3] (line 12)", or a row "packing.csv:4".
std::string Placement::name(std::size_t i) {
  if (i < tables_.size())
    return fmt::format("particle[{}] (line {})", i, scene_.particles[i].source_line);
  return fmt::format("{}:{}", file_of(i).shown, scene_.particles[i].source_line);
}

// At a table's position, or at the CSV row ("fill[2].file row: position = [x, y]: ...").
void Placement::report(std::size_t i, std::string_view what) {
  if (i < tables_.size()) {
    TableReader(diag_, *tables_[i], kParticle, i).invalid("position", what);
    return;
  }
  FileRows& file = file_of(i);
  if (++file.reported > kMaxCsvErrors) return;
  const ParticleSpec& p = scene_.particles[i];
  diag_.add(fmt::format("{}:{}: error: fill[{}].file row: position = [{:g}, {:g}]: {}", file.shown,
                        p.source_line, file.fill, p.position.x, p.position.y, what));
}

}  // namespace dem2d::deck
