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
#include "core/setup/size_law.hpp"
#include "core/setup/validate.hpp"
#include "core/shape/disc.hpp"

namespace dem2d {

namespace {

// "deck.in:14:9: error: fill[0].count = 5000: ", at the key that sets how many the fill places
// (Scene::where), else at the fill's line.
std::string where(const Scene& scene, const FillSpec& s) {
  const std::string fill = "fill[" + std::to_string(s.index) + "]";
  std::ostringstream value;
  std::string key = fill + ".count";
  if (s.count > 0) {
    value << s.count;
  } else if (s.bed_filling > 0.0) {
    key = fill + ".bed_filling";
    value << s.bed_filling;
  } else {
    key = fill + ".fill_fraction";
    value << s.fill_fraction;
  }
  const auto it = scene.where.find(key);
  if (it == scene.where.end())
    return scene.deck_path + ":" + std::to_string(s.source_line) + ": error: " + fill + ": ";
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
  if (s.count > 0) return s.count;  // a table apportions exactly its count
  return static_cast<std::int64_t>(fill_radii(scene, f).size());
}

namespace {

// A free site of a fill's lattice and its sort key (the order the region fills it in).
struct Site {
  Vec2 x;
  double key;
};

// The sites of fill f (and the fills mixed with it): a triangular lattice of spacing 2.1
// radius_max (the group's largest) over the region, minus the sites that touch a wall or a
// particle already placed, each with its key (random for `full` and `box`, by row for
// `bottom`, by distance from the shell for `annulus`).
std::vector<Site> fill_sites(const Scene& scene, const Walls& walls, const ParticleStore& store,
                             std::size_t f, double radius_max, double r_all_max) {
  const FillSpec& s = scene.fills[f];
  const bool needs_drum = s.region != FillRegion::kBox;
  const DrumGeometry drum(scene.drum);
  const double spacing = 2.1 * radius_max;
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

// Fills [first, last) placed together: one fill, or one and the fills after it that mix with it
// (mix = true), on one lattice of spacing 2.1 radius_max, the group's largest.
struct Group {
  std::size_t first = 0, last = 0;
  double radius_max = 0.0;
};

std::string group_names(const Group& g, const Scene& scene) {
  std::string names;
  for (std::size_t f = g.first; f < g.last; ++f)
    names += (f == g.first      ? ""
              : f + 1 == g.last ? " and "
                                : ", ") +
             std::string("fill[") + std::to_string(scene.fills[f].index) + "]";
  return names;
}

// The site (index into the sorted sites) of each particle of the group, in id order: the
// identity for one fill; for mixed fills a permutation by (seed, first fill), so that each
// fill's particles are spread over the group's sites in proportion to their numbers.
std::vector<std::size_t> group_sites(const Scene& scene, const Group& g, std::size_t n) {
  std::vector<std::size_t> site(n);
  for (std::size_t k = 0; k < n; ++k) site[k] = k;
  if (g.last - g.first < 2) return site;
  for (std::size_t i = n; i > 1; --i) {  // Fisher-Yates
    const double u = random_uniform(scene.run.seed, kFillStream + 4000 + g.first, i - 1);
    std::swap(site[i - 1],
              site[std::min(static_cast<std::size_t>(u * static_cast<double>(i)), i - 1)]);
  }
  return site;
}

// Places the particles of one group at its lattice's first sites, each jittered within its
// site's slack; an error when the region cannot hold them (placing nothing).
void place_group(const Scene& scene, const Walls& walls, ParticleStore& store, const Group& g,
                 double r_all_max, std::int64_t& next_id, std::vector<std::string>& errors) {
  const FillSpec& head = scene.fills[g.first];
  if (head.region != FillRegion::kBox && !scene.drum.present) {
    errors.push_back(where(scene, head) +
                     "region needs a [drum]; use region = \"box\" with box_min and box_max");
    return;
  }
  std::vector<std::vector<double>> radii;
  std::size_t n = 0;
  for (std::size_t f = g.first; f < g.last; ++f) {
    radii.push_back(fill_radii(scene, f));
    n += radii.back().size();
  }
  std::vector<Site> sites = fill_sites(scene, walls, store, g.first, g.radius_max, r_all_max);
  if (sites.size() < n) {
    std::ostringstream o;
    o << n << " particles do not fit: the region holds " << sites.size()
      << " clear of the walls and the particles placed before, at radius_max " << g.radius_max
      << " m";
    if (g.last - g.first > 1) o << " (" << group_names(g, scene) << " mixed)";
    o << "; lower count, fill_fraction or bed_filling, or enlarge the region";
    errors.push_back(where(scene, head) + o.str());
    return;
  }
  std::stable_sort(sites.begin(), sites.end(),
                   [](const Site& a, const Site& b) { return a.key < b.key; });
  const std::vector<std::size_t> site = group_sites(scene, g, n);
  const double spacing = 2.1 * g.radius_max;  // as in fill_sites
  const double half = 0.5 * spacing;
  std::size_t first = 0;  // the fill's first particle in the group
  for (std::size_t f = g.first; f < g.last; ++f) {
    const FillSpec& s = scene.fills[f];
    const int mat = find_material(scene, s.material);
    const std::vector<double>& r = radii[f - g.first];
    for (std::size_t k = 0; k < r.size(); ++k) {
      // Jitter within the site's slack: the site's circle of radius spacing/2 holds the sphere.
      const double slack = half - r[k];
      const double jx = random_uniform(scene.run.seed, kFillStream + 2000 + f, 2 * k) * 2.0 - 1.0;
      const double jy =
          random_uniform(scene.run.seed, kFillStream + 2000 + f, 2 * k + 1) * 2.0 - 1.0;
      const Vec2 x = sites[site[first + k]].x + (slack * 0.7071) * Vec2{jx, jy};
      store.add(next_id++, mat, r[k], scene.materials[mat].density, x, s.velocity, 0.0);
    }
    first += r.size();
  }
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

  for (std::size_t f = 0; f < scene.fills.size();) {
    Group g{f, f + 1, scene.fills[f].radius_max};
    while (g.last < scene.fills.size() && scene.fills[g.last].mix)
      g.radius_max = std::max(g.radius_max, scene.fills[g.last++].radius_max);
    place_group(scene, walls, store, g, r_all_max, next_id, errors);
    f = g.last;
  }
  if (!errors.empty()) throw InputError(errors);
}

}  // namespace dem2d
