#include "core/setup/fill.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/base/errors.hpp"
#include "core/base/random.hpp"
#include "core/geometry/drum_geometry.hpp"
#include "core/setup/validate.hpp"
#include "core/shape/disc.hpp"

namespace dem2d {

namespace {

constexpr std::uint64_t kFillStream = 0xF111ULL << 32;

double fill_radius(const Scene& scene, std::size_t f, std::int64_t k) {
  const FillSpec& s = scene.fills[f];
  if (s.radius_max <= s.radius_min) return s.radius_min;
  const double u = random_uniform(scene.run.seed, kFillStream + f, static_cast<std::uint64_t>(k));
  return s.radius_min + u * (s.radius_max - s.radius_min);
}

// "deck.in:14:9: error: fill[0].count = 5000: ", at the key that sets how many the fill places
// (Scene::where), else at the fill's line.
std::string where(const Scene& scene, const FillSpec& s) {
  const std::string fill = "fill[" + std::to_string(s.index) + "]";
  const std::string key = fill + (s.count > 0 ? ".count" : ".fill_fraction");
  const auto it = scene.where.find(key);
  if (it == scene.where.end())
    return scene.deck_path + ":" + std::to_string(s.source_line) + ": error: " + fill + ": ";
  std::ostringstream value;
  if (s.count > 0) {
    value << s.count;
  } else {
    value << s.fill_fraction;
  }
  return it->second + ": error: " + key + " = " + value.str() + ": ";
}

// Uniform grid of placed particles for overlap checks.
class PlacedGrid {
 public:
  PlacedGrid(const ParticleStore& p, double cell) : p_(p), h_(cell) {
    for (std::size_t k = 0; k < p.size(); ++k) insert(k);
  }
  void insert(std::size_t k) { cells_[key(p_.pos[k])].push_back(k); }
  bool overlaps(Vec2 x, double r, double r_max) const {
    const auto [cx, cy] = index(x);
    const int reach = static_cast<int>(std::ceil((r + r_max) / h_));
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx) {
        auto it = cells_.find(pack(cx + dx, cy + dy));
        if (it == cells_.end()) continue;
        for (std::size_t k : it->second) {
          const double s = r + p_.radius[k];
          if (norm2(p_.pos[k] - x) < s * s) return true;
        }
      }
    return false;
  }

 private:
  std::pair<long, long> index(Vec2 x) const {
    return {static_cast<long>(std::floor(x.x / h_)), static_cast<long>(std::floor(x.y / h_))};
  }
  static long long pack(long x, long y) {
    return (static_cast<long long>(x) << 32) ^ (y & 0xffffffffLL);
  }
  long long key(Vec2 x) const {
    const auto [a, b] = index(x);
    return pack(a, b);
  }
  const ParticleStore& p_;
  double h_;
  std::unordered_map<long long, std::vector<std::size_t>> cells_;
};

}  // namespace

std::int64_t fill_count(const Scene& scene, std::size_t f) {
  const FillSpec& s = scene.fills[f];
  if (s.count > 0) return s.count;
  const double target = s.fill_fraction * std::numbers::pi * scene.drum.radius * scene.drum.radius;
  double area = 0.0;
  std::int64_t k = 0;
  while (area < target) {
    const double r = fill_radius(scene, f, k);
    area += std::numbers::pi * r * r;
    ++k;
  }
  return k;
}

namespace {

// A free site of a fill's lattice and its sort key (the order the region fills it in).
struct Site {
  Vec2 x;
  double key;
};

// The sites of fill f: a triangular lattice of spacing 2.1 radius_max over the region, minus
// the sites that touch a wall or a particle already placed, each with its key (random for
// `full` and `box`, by row for `bottom`, by distance from the shell for `annulus`).
std::vector<Site> fill_sites(const Scene& scene, const Walls& walls, const ParticleStore& store,
                             std::size_t f, double r_all_max) {
  const FillSpec& s = scene.fills[f];
  const bool needs_drum = s.region != FillRegion::kBox;
  const DrumGeometry drum(scene.drum);
  const double spacing = 2.1 * s.radius_max;
  const double row = spacing * std::sqrt(3.0) / 2.0;
  Vec2 lo = s.box_min, hi = s.box_max;
  const Vec2 c = scene.drum.center;
  double r_in = 0.0;
  if (needs_drum) {
    r_in = drum.inner_radius();
    lo = c - Vec2{r_in, r_in};
    hi = c + Vec2{r_in, r_in};
  }
  PlacedGrid placed(store, 2.0 * r_all_max);
  const double half = 0.5 * spacing;
  std::vector<Site> sites;
  long row_index = 0;
  for (double y = lo.y + half; y <= hi.y - half + 1e-12; y += row, ++row_index) {
    const double x0 = lo.x + half + ((row_index % 2) ? half : 0.0);
    for (double x = x0; x <= hi.x - half + 1e-12; x += spacing) {
      const Vec2 p{x, y};
      if (needs_drum && norm(p - c) > r_in - half) continue;
      bool clear = true;
      for (int e = 0; e < static_cast<int>(walls.elements().size()) && clear; ++e)
        if (Disc::wall(walls, e, p, half).delta > 0.0) clear = false;
      if (clear && drum.bar_overlap(p, half)) clear = false;  // also inside a bar
      if (!clear || placed.overlaps(p, half, r_all_max)) continue;
      const std::uint64_t id = sites.size();
      const double u = random_uniform(scene.run.seed, kFillStream + 1000 + f, id);
      double key = u;  // full, box: random order
      if (s.region == FillRegion::kBottom) key = static_cast<double>(row_index) + u;
      if (s.region == FillRegion::kAnnulus) key = -norm(p - c) + 1e-3 * u * spacing;
      sites.push_back({p, key});
    }
  }
  return sites;
}

}  // namespace

void place_particles(const Scene& scene, const Walls& walls, ParticleStore& store) {
  check_memory(scene, physical_memory_bytes());  // before anything is allocated
  std::vector<std::string> errors;
  std::int64_t next_id = static_cast<std::int64_t>(store.size());
  for (const ParticleSpec& s : scene.particles) {
    const int mat = find_material(scene, s.material);
    store.add(next_id++, mat, s.radius, scene.materials[mat].density, s.position, s.velocity,
              s.spin);
  }
  double r_all_max = 0.0;
  for (std::size_t k = 0; k < store.size(); ++k) r_all_max = std::max(r_all_max, store.radius[k]);
  for (const FillSpec& s : scene.fills) r_all_max = std::max(r_all_max, s.radius_max);
  if (r_all_max <= 0.0) return;

  for (std::size_t f = 0; f < scene.fills.size(); ++f) {
    const FillSpec& s = scene.fills[f];
    if (s.region != FillRegion::kBox && !scene.drum.present) {
      errors.push_back(where(scene, s) +
                       "region needs a [drum]; use region = \"box\" with box_min and box_max");
      continue;
    }
    const std::int64_t n = fill_count(scene, f);
    std::vector<Site> sites = fill_sites(scene, walls, store, f, r_all_max);
    if (static_cast<std::int64_t>(sites.size()) < n) {
      std::ostringstream o;
      o << n << " particles do not fit: the region holds " << sites.size()
        << " clear of the walls and the particles placed before, at radius_max " << s.radius_max
        << " m; lower count or fill_fraction, or enlarge the region";
      errors.push_back(where(scene, s) + o.str());
      continue;
    }
    std::stable_sort(sites.begin(), sites.end(),
                     [](const Site& a, const Site& b) { return a.key < b.key; });
    const int mat = find_material(scene, s.material);
    const double spacing = 2.1 * s.radius_max;  // as in fill_sites
    const double half = 0.5 * spacing;
    for (std::int64_t k = 0; k < n; ++k) {
      const double r = fill_radius(scene, f, k);
      // Jitter within the site's slack: the site's circle of radius spacing/2 holds the sphere.
      const double slack = half - r;
      const double jx = random_uniform(scene.run.seed, kFillStream + 2000 + f, 2 * k) * 2.0 - 1.0;
      const double jy =
          random_uniform(scene.run.seed, kFillStream + 2000 + f, 2 * k + 1) * 2.0 - 1.0;
      const Vec2 x = sites[k].x + (slack * 0.7071) * Vec2{jx, jy};
      store.add(next_id++, mat, r, scene.materials[mat].density, x, s.velocity, 0.0);
    }
  }
  if (!errors.empty()) throw InputError(errors);
}

}  // namespace dem2d
