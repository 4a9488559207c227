#include "io/checkpoint_checks.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include "core/geometry/drum_geometry.hpp"
#include "core/geometry/walls.hpp"
#include "io/hdf5.hpp"
#include "io/placement.hpp"

namespace dem2d {
namespace {

// splitmix64's finalizer: a bijection of 64-bit words that spreads every bit over all of them.
std::uint64_t mix(std::uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// A row's bytes, 8 at a time, each folded in through the bijection: a row that differs in one
// word hashes differently.
std::uint64_t row_hash(const std::byte* row, std::size_t bytes) {
  std::uint64_t h = mix(0x9e3779b97f4a7c15ULL + bytes);
  for (std::size_t k = 0; k < bytes; k += 8) {
    std::uint64_t word = 0;
    std::memcpy(&word, row + k, std::min<std::size_t>(8, bytes - k));
    h = mix(h ^ word);
  }
  return h;
}

std::string dataset(const FieldBase& f) { return "/particles/" + f.name(); }

// The columns of a resumption by field, read as the values they hold.
class Columns {
 public:
  Columns(const ParticleStore& layout, const Resumption& r) : layout_(layout), r_(r) {}
  std::size_t n() const { return r_.n_particles; }
  const FieldBase& field(std::size_t f) const { return *layout_.fields()[f]; }
  std::size_t count() const { return layout_.fields().size(); }
  // The column of the field called `name` (every scene's store has it).
  std::size_t index(const std::string& name) const {
    const auto& fs = layout_.fields();
    return static_cast<std::size_t>(
        std::find_if(fs.begin(), fs.end(), [&](const FieldBase* f) { return f->name() == name; }) -
        fs.begin());
  }
  bool is_real(std::size_t f) const { return h5::memory_type(field(f)) == H5T_NATIVE_DOUBLE; }
  std::size_t per_item(std::size_t f) const { return field(f).bytes_per_item() / 8; }
  double real(std::size_t f, std::size_t k, std::size_t c = 0) const {
    double x = 0.0;
    std::memcpy(&x, r_.columns[f].data() + (k * per_item(f) + c) * 8, 8);
    return x;
  }
  std::int64_t id(std::size_t k) const {
    std::int64_t x = 0;
    std::memcpy(&x, r_.columns[index("id")].data() + k * 8, 8);
    return x;
  }
  std::int32_t material(std::size_t k) const {
    std::int32_t x = 0;
    std::memcpy(&x, r_.columns[index("material")].data() + k * 4, 4);
    return x;
  }
  Vec2 position(std::size_t k) const {
    const std::size_t f = index("position");
    return {real(f, k, 0), real(f, k, 1)};
  }

 private:
  const ParticleStore& layout_;
  const Resumption& r_;
};

std::string id_problem(const Columns& c) {
  std::vector<std::pair<std::int64_t, std::size_t>> ids(c.n());
  for (std::size_t k = 0; k < c.n(); ++k) {
    ids[k] = {c.id(k), k};
    if (ids[k].first < 0) return fmt::format("/particles/id: row {} holds id {} (< 0)", k, c.id(k));
  }
  std::sort(ids.begin(), ids.end());
  for (std::size_t k = 1; k < ids.size(); ++k)
    if (ids[k].first == ids[k - 1].first)
      return fmt::format("/particles/id: particle id {} appears twice (rows {} and {})",
                         ids[k].first, ids[k - 1].second, ids[k].second);
  return {};
}

// Every value finite; radii, masses and inverse masses and inertias above 0.
std::string value_problem(const Columns& c) {
  constexpr const char* kPositive[] = {"radius", "mass", "inv_mass", "inv_inertia"};
  constexpr const char* kAxis[] = {"x", "y"};
  for (std::size_t f = 0; f < c.count(); ++f) {
    if (!c.is_real(f)) continue;
    const std::string& name = c.field(f).name();
    const bool positive = std::ranges::find(kPositive, name) != std::end(kPositive);
    const std::size_t per = c.per_item(f);
    for (std::size_t k = 0; k < c.n(); ++k)
      for (std::size_t v = 0; v < per; ++v) {
        const double x = c.real(f, k, v);
        if (std::isfinite(x) && (!positive || x > 0.0)) continue;
        const std::string what = per == 2 ? fmt::format("{} {}", name, kAxis[v]) : name;
        return fmt::format("{}: particle {} has {} = {}{}", dataset(c.field(f)), c.id(k), what, x,
                           std::isfinite(x) ? "; it must be > 0" : "");
      }
  }
  return {};
}

std::string material_problem(const Scene& scene, const Columns& c) {
  const auto materials = static_cast<std::int32_t>(scene.materials.size());
  for (std::size_t k = 0; k < c.n(); ++k)
    if (c.material(k) < 0 || c.material(k) >= materials)
      return fmt::format(
          "/particles/material: particle {} has material {}; the deck has {} "
          "materials (0 to {})",
          c.id(k), c.material(k), materials, materials - 1);
  return {};
}

// Inside the drum and clear of its bars at the checkpoint's time, as the deck's particles must be
// at the start: each position turned back by the angle the drum has turned since.
std::string containment_problem(const Scene& scene, const Columns& c, double time) {
  const DrumSpec& d = scene.drum;
  if (!d.present) return {};
  const DrumGeometry drum(d);
  const double turned = ramp_angle(d.speed, d.ramp_time, time);
  const double tolerance = deck::Placement::kPlacementOverlap;
  const std::size_t radius = c.index("radius");
  const std::string where = fmt::format("the drum (radius {:g} m about [{:g}, {:g}]) at t = {:g} s",
                                        d.radius, d.center.x, d.center.y, time);
  for (std::size_t k = 0; k < c.n(); ++k) {
    const Vec2 x = c.position(k);
    const double r = c.real(radius, k);
    const Vec2 at_start = d.center + rotate(x - d.center, -turned);
    const double overlap = r - drum.shell_clearance(at_start);
    // Formatted only for the particle at fault: the loop runs over every particle.
    const auto particle = [&] {
      return fmt::format("/particles/position: particle {} (radius {:g} m) at [{:g}, {:g}]",
                         c.id(k), r, x.x, x.y);
    };
    if (overlap >= r + r) return fmt::format("{} lies outside {}", particle(), where);
    if (overlap > tolerance * r)
      return fmt::format(
          "{} overlaps the shell of {} by {:.3g} % of its radius; at most {:g} % "
          "is allowed",
          particle(), where, 100.0 * overlap / r, 100.0 * tolerance);
    if (const auto bar = drum.bar_overlap(at_start, r - tolerance * r))
      return fmt::format("{} {} bar {} of drum.lifter[{}] at t = {:g} s", particle(),
                         bar->inside ? "lies inside" : "overlaps", bar->bar, bar->lifter, time);
  }
  return {};
}

std::string history_problem(const HistoryRecords& h) {
  for (std::size_t k = 0; k < h.size(); ++k)
    for (std::size_t v = 0; v < h.width(); ++v)
      if (!std::isfinite(h.values(k)[v]))
        return fmt::format(
            "/contacts/history: the contact of particle {} and {} {} has value {} "
            "= {}",
            h.a(k), h.b(k) < 0 ? "wall element" : "particle", h.b(k) < 0 ? -h.b(k) - 1 : h.b(k), v,
            h.values(k)[v]);
  return {};
}

}  // namespace

std::uint64_t rows_checksum(const std::byte* data, std::size_t rows, std::size_t row_bytes) {
  std::uint64_t sum = 0;
  for (std::size_t k = 0; k < rows; ++k) sum += row_hash(data + k * row_bytes, row_bytes);
  return sum;
}

std::string resumption_problem(const Scene& scene, const ParticleStore& layout,
                               const Resumption& r) {
  const Columns c(layout, r);
  for (const std::string& problem : {id_problem(c), value_problem(c), material_problem(scene, c)})
    if (!problem.empty()) return problem;
  if (std::string problem = containment_problem(scene, c, r.state.time); !problem.empty())
    return problem;
  if (is_ore_scene(scene)) {
    std::int64_t largest = -1;
    for (std::size_t k = 0; k < c.n(); ++k) largest = std::max(largest, c.id(k));
    if (r.state.grinding.next_id <= largest)
      return fmt::format(
          "the attribute next_id = {} is not above the largest particle id {}: "
          "new particles would take ids in use",
          r.state.grinding.next_id, largest);
  }
  return history_problem(r.histories);
}

}  // namespace dem2d
