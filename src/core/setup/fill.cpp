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
#include "core/shape/superellipse_sizing.hpp"

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

// Uniform grid of placed particles (their centres and radii) for overlap checks.
class PlacedGrid {
 public:
  PlacedGrid(const ParticleStore& p, double cell) : h_(cell) {
    for (std::size_t k = 0; k < p.size(); ++k) insert(p.pos[k], p.radius[k]);
  }
  void insert(Vec2 x, double r) { cells_[key(x)].push_back({x, r}); }
  bool overlaps(Vec2 x, double r, double r_max) const {
    const auto [cx, cy] = index(x);
    const int reach = static_cast<int>(std::ceil((r + r_max) / h_));
    for (int dy = -reach; dy <= reach; ++dy)
      for (int dx = -reach; dx <= reach; ++dx) {
        auto it = cells_.find(pack(cx + dx, cy + dy));
        if (it == cells_.end()) continue;
        for (const Disc& d : it->second) {
          const double s = r + d.r;
          if (norm2(d.x - x) < s * s) return true;
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
  struct Disc {
    Vec2 x;
    double r;
  };
  double h_;
  std::unordered_map<long long, std::vector<Disc>> cells_;
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

// The sites of fill f: a triangular lattice of spacing 2.1 radius_max over the region, minus
// the sites that touch a wall or a particle already placed, each with its key (random for
// `full` and `box`, by row for `bottom`, by distance from the shell for `annulus`).
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
// (mix = true).
struct Group {
  std::size_t first = 0, last = 0;
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

// Jitter of particle k of fill f within its site's slack, half - r: the site's circle of radius
// half (half the spacing) holds the sphere.
Vec2 jitter(const Scene& scene, std::size_t f, std::size_t k, double slack) {
  const double jx = random_uniform(scene.run.seed, kFillStream + 2000 + f, 2 * k) * 2.0 - 1.0;
  const double jy = random_uniform(scene.run.seed, kFillStream + 2000 + f, 2 * k + 1) * 2.0 - 1.0;
  return (slack * 0.7071) * Vec2{jx, jy};
}

// The radius of the circle that holds a particle of fill s of (volume-equivalent) radius r.
double held_radius(const FillSpec& s, double r) {
  if (s.shape == ParticleShape::kDisc) return r;
  return r * bounding_factor(s.aspect, s.exponent);
}

// Particle k of fill f, of (volume-equivalent) radius r, at x: a disc, or a superellipse turned
// by an angle uniform in [0, 2 pi) keyed by (seed, fill, particle).
void add_filled(const Scene& scene, ParticleStore& store, std::size_t f, std::size_t k,
                std::int64_t id, int mat, double r, Vec2 x) {
  const FillSpec& s = scene.fills[f];
  const double density = scene.materials[mat].density;
  if (s.shape == ParticleShape::kDisc) {
    store.add(id, mat, r, density, x, s.velocity, 0.0);
    return;
  }
  const SuperEllipse e = superellipse_of_size(r, s.aspect, s.exponent);
  const double angle =
      2.0 * std::numbers::pi * random_uniform(scene.run.seed, kFillStream + 5000 + f, k);
  store.add_shaped(id, mat, e.a, e.b, e.n, density, x, s.velocity, 0.0, angle);
}

std::string do_not_fit(const Scene& scene, std::size_t f, std::size_t n, std::size_t sites,
                       const std::string& mixed) {
  std::ostringstream o;
  o << n << " particles do not fit: the region holds " << sites
    << " clear of the walls and the particles placed before, at radius_max "
    << scene.fills[f].radius_max << " m" << mixed
    << "; lower count, fill_fraction or bed_filling, or enlarge the region";
  return where(scene, scene.fills[f]) + o.str();
}

// One fill alone: its particles at the first sites of its lattice, in id order.
void place_fill(const Scene& scene, const Walls& walls, ParticleStore& store, std::size_t f,
                double r_all_max, std::int64_t& next_id, std::vector<std::string>& errors) {
  const FillSpec& s = scene.fills[f];
  const std::vector<double> r = fill_radii(scene, f);
  const double r_place = placement_radius_max(s);
  std::vector<Site> sites = fill_sites(scene, walls, store, f, r_place, r_all_max);
  if (sites.size() < r.size()) {
    errors.push_back(do_not_fit(scene, f, r.size(), sites.size(), ""));
    return;
  }
  std::stable_sort(sites.begin(), sites.end(),
                   [](const Site& a, const Site& b) { return a.key < b.key; });
  const int mat = find_material(scene, s.material);
  const double spacing = 2.1 * r_place;  // as in fill_sites
  const double half = 0.5 * spacing;
  for (std::size_t k = 0; k < r.size(); ++k) {
    const Vec2 x = sites[k].x + jitter(scene, f, k, half - held_radius(s, r[k]));
    add_filled(scene, store, f, k, next_id++, mat, r[k], x);
  }
}

// Mixed fills: each keeps its own lattice, sorted as its region says; the group's particles
// are dealt in an order shuffled by (seed, first fill), each fill's in proportion to their
// numbers, and each takes the next site of its own lattice (the lowest free one for "bottom")
// that is clear of the particles the group placed before it. Ids follow the deck's order.
void place_mixed(const Scene& scene, const Walls& walls, ParticleStore& store, const Group& g,
                 double r_all_max, std::int64_t& next_id, std::vector<std::string>& errors) {
  const std::size_t m = g.last - g.first;
  std::vector<std::vector<double>> radii(m);
  std::vector<std::vector<Site>> sites(m);
  std::vector<std::vector<Vec2>> at(m);
  std::vector<std::size_t> owner;  // the fill (0 .. m-1) of each particle dealt
  for (std::size_t i = 0; i < m; ++i) {
    const std::size_t f = g.first + i;
    radii[i] = fill_radii(scene, f);
    sites[i] = fill_sites(scene, walls, store, f, placement_radius_max(scene.fills[f]), r_all_max);
    std::stable_sort(sites[i].begin(), sites[i].end(),
                     [](const Site& a, const Site& b) { return a.key < b.key; });
    owner.insert(owner.end(), radii[i].size(), i);
  }
  for (std::size_t j = owner.size(); j > 1; --j) {  // Fisher-Yates
    const double u = random_uniform(scene.run.seed, kFillStream + 4000 + g.first, j - 1);
    std::swap(owner[j - 1],
              owner[std::min(static_cast<std::size_t>(u * static_cast<double>(j)), j - 1)]);
  }
  PlacedGrid placed(store, 2.0 * r_all_max);
  std::vector<std::size_t> next(m, 0);
  for (const std::size_t i : owner) {
    const std::size_t f = g.first + i, k = at[i].size();
    const double r = held_radius(scene.fills[f], radii[i][k]);
    const Vec2 offset = jitter(scene, f, k, 0.5 * (2.1 * placement_radius_max(scene.fills[f])) - r);
    while (next[i] < sites[i].size() && placed.overlaps(sites[i][next[i]].x + offset, r, r_all_max))
      ++next[i];
    if (next[i] == sites[i].size()) {
      errors.push_back(
          do_not_fit(scene, f, radii[i].size(), k,
                     " beside the fills it mixes with (" + group_names(g, scene) + ")"));
      return;
    }
    at[i].push_back(sites[i][next[i]++].x + offset);
    placed.insert(at[i].back(), r);
  }
  for (std::size_t i = 0; i < m; ++i) {
    const FillSpec& s = scene.fills[g.first + i];
    const int mat = find_material(scene, s.material);
    for (std::size_t k = 0; k < at[i].size(); ++k)
      add_filled(scene, store, g.first + i, k, next_id++, mat, radii[i][k], at[i][k]);
  }
}

// One group: one fill placed alone, or mixed fills placed together.
void place_group(const Scene& scene, const Walls& walls, ParticleStore& store, const Group& g,
                 double r_all_max, std::int64_t& next_id, std::vector<std::string>& errors) {
  const FillSpec& head = scene.fills[g.first];
  if (head.region != FillRegion::kBox && !scene.drum.present) {
    errors.push_back(where(scene, head) +
                     "region needs a [drum]; use region = \"box\" with box_min and box_max");
    return;
  }
  if (g.last - g.first == 1) {
    place_fill(scene, walls, store, g.first, r_all_max, next_id, errors);
  } else {
    place_mixed(scene, walls, store, g, r_all_max, next_id, errors);
  }
}

}  // namespace

void place_particles(const Scene& scene, const Walls& walls, ParticleStore& store) {
  check_memory(scene, physical_memory_bytes());  // before anything is allocated
  std::vector<std::string> errors;
  std::int64_t next_id = static_cast<std::int64_t>(store.size());
  for (const ParticleSpec& s : scene.particles) {
    const int mat = find_material(scene, s.material);
    if (s.shaped())
      store.add_shaped(next_id++, mat, s.semi_a, s.semi_b, s.exponent, scene.materials[mat].density,
                       s.position, s.velocity, s.spin, s.angle);
    else
      store.add(next_id++, mat, s.radius, scene.materials[mat].density, s.position, s.velocity,
                s.spin);
  }
  double r_all_max = 0.0;
  for (std::size_t k = 0; k < store.size(); ++k) r_all_max = std::max(r_all_max, store.radius[k]);
  for (const FillSpec& s : scene.fills) r_all_max = std::max(r_all_max, placement_radius_max(s));
  if (r_all_max <= 0.0) return;

  for (std::size_t f = 0; f < scene.fills.size();) {
    Group g{f, f + 1};
    while (g.last < scene.fills.size() && scene.fills[g.last].mix) ++g.last;
    place_group(scene, walls, store, g, r_all_max, next_id, errors);
    f = g.last;
  }
  if (!errors.empty()) throw InputError(errors);
}

}  // namespace dem2d
