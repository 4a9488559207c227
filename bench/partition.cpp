// partition: the angular-sector partition in partition-only mode (no stepping): load balance and
// halo size of the METIS-weighted sector partition against equal angles, for a settled charge
// of 30 000 spheres and charges of 300 000 and 1 000 000 spheres, at 2 .. 256 ranks.
//
// Charges (drum centre (0, 0)).
// (a) The settled 30 000-sphere charge of bench/throughput (bench/settled_drum.hpp), read from
//     bench/results/cache/settled_drum_30000.csv (x, y, radius, vx, vy, spin; drum radius
//     2.5 m). If the file is missing the program says how to make it and exits 1.
// (b), (c) N = 300 000 and 1 000 000 spheres in a drum of radius 2.5 sqrt(N / 30 000) m
//     (7.91 m and 14.43 m), built without simulation by tiling the settled packing: a
//     rectangular patch is cut from the interior of charge (a): |x| < 0.64 R, from 0.02 R above
//     the drum shell at x = 0.64 R up to 0.05 R below the bed surface (the 99th percentile of
//     y) - about half the charge. Copies of the patch, placed side by side with the patch's
//     width and height as periods, cover the big drum; a copy's particle is kept if it lies
//     inside the drum (|x| + r <= R') and overlaps no particle kept before it by more than
//     0.1 mm (the seams between copies cut through the packing: a kept-first rule on a cell
//     grid removes the seam overlaps; the settled contacts overlap by micrometres and are
//     kept). The N lowest of the kept particles (by y, then x) are the charge: a circular
//     segment at the bottom of the drum with a flat top, the shape of charge (a) scaled by
//     sqrt(N / 30 000) (the program prints the two surface heights; the seams' gaps make the
//     packing slightly looser, so the surface sits slightly higher). Area fraction of the bed
//     ~0.77 as in (a).
//
// Per configuration (charge, work variant, nranks in {2, 4, ..., 256}, sectors per rank
// spr in {16, 24, 32, 48, 64, 96, 128}; n = nranks spr sectors, up to 32 768):
//  - work per sector: "particles": particles per sector (sector_of, the ownership rule);
//    "contacts" (charge (a) only): pairs with |x_i - x_j| < r_i + r_j + skin, skin =
//    0.4 r_min = 2.4 mm (cell grid), each pair counting 1/2 in the sector of each particle;
//  - boundary weight of the edge between sectors s and s + 1: the particles within the halo
//    width h = 2 r_max + skin = 22.4 mm of the boundary ray between them (the ray at angle
//    (s + 1) 2 pi / n; distance to a ray as in sector_partition.hpp);
//  - partitions: partition_metis (METIS + refinement, exact-ring fallback) and
//    partition_equal_angle; imbalance = max rank work / mean rank work;
//  - halo: the ghosts of rank k are the particles owned by another rank whose distance to k's
//    wedge (distance_to_part) is below h. For each particle only the ranks owning a sector
//    within the angle asin(h / |x|) (+- one sector) can qualify (all ranks if |x| <= h): O(N)
//    per partition, no O(N^2). Reported: mean and max ghosts per rank, ghosts / owned (total
//    ghosts over N), the largest ghosts / owned of one rank (ranks owning particles) and how
//    many ranks hold more ghosts than half their owned particles, and the narrowest wedge (an
//    arc's angle, and its width at the shell) of the ranks that own particles.
// The whole sweep, 448 partitions, takes about 30 s of CPU (2026-11-26; the 1e6 charge's 112
// about 60 % of it), so no charge needs a shorter one.
// Output: a table (imbalance at 16, 32 and 64 sectors per rank, the fewest sectors per rank
// with which the METIS partition reaches 5 %, the halo at 32, the default), the rank counts
// from which the halo passes half the owned particles, bench/results/partition.csv (every
// configuration) and bench/results/partition.png (post/plot_partition.py through std::system;
// --no-plot skips).
//
//   partition [--no-plot] [--results DIR]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/base/vec2.hpp"
#include "parallel/sector_partition.hpp"
#include "settled_drum.hpp"

namespace {

using dem2d::SectorPartition;
using dem2d::Vec2;
using Clock = std::chrono::steady_clock;

using bench::kRadiusMax;
using bench::kRadiusMin;
using bench::kRefDrum;
constexpr double kSkin = 0.4 * kRadiusMin;
constexpr double kHalo = 2.0 * kRadiusMax + kSkin;
constexpr double kTarget = 1.05;
constexpr double kHaloLimit = 0.5;  // "the halo passes half the owned particles"
const std::vector<int> kRanks{2, 4, 8, 16, 32, 64, 128, 256};
const std::vector<int> kSectorsPerRank{16, 24, 32, 48, 64, 96, 128};
constexpr int kDefaultSpr = 32;  // DecompositionOptions

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The q-quantile of the particles' heights.
double percentile_y(const std::vector<dem2d::Vec2>& x, double q) {
  std::vector<double> y;
  y.reserve(x.size());
  for (dem2d::Vec2 p : x) y.push_back(p.y);
  const auto k = static_cast<std::size_t>(q * static_cast<double>(y.size() - 1));
  std::nth_element(y.begin(), y.begin() + static_cast<std::ptrdiff_t>(k), y.end());
  return y[k];
}

// The tiling of the large charges (until 2026-11-26 also bench/throughput's drums): copies of a
// rectangular patch of a settled packing (positions x, radii r, drum radius R) cover a drum of
// radius Rb; a copy's particle is kept if it lies inside the drum and overlaps no particle kept
// before it by more than `allowed`; the n_target lowest kept (by y, then x) are the charge.
struct Tiling {
  std::vector<dem2d::Vec2> pos;
  std::vector<double> radius;
  double half = 0.0, y0 = 0.0, y1 = 0.0, surface = 0.0;  // the patch; the source's 99th pct. y
  std::size_t patch = 0, candidates = 0, kept = 0;
  int cols = 0, rows = 0;
};
Tiling tile(const std::vector<dem2d::Vec2>& x, const std::vector<double>& r, double R, double Rb,
            std::int64_t n_target, double allowed) {
  Tiling t;
  t.surface = percentile_y(x, 0.99);
  t.half = 0.64 * R;
  t.y0 = -std::sqrt(R * R - t.half * t.half) + 0.02 * R;
  t.y1 = t.surface - 0.05 * R;
  const double w = 2.0 * t.half, h = t.y1 - t.y0;
  std::vector<std::size_t> patch;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (std::abs(x[i].x) < t.half && x[i].y >= t.y0 && x[i].y < t.y1) patch.push_back(i);
  const double top = t.surface * (Rb / R) + 0.1 * Rb;  // generous: trimmed to n_target below
  t.cols = static_cast<int>(std::ceil(2.0 * Rb / w)) + 1;
  t.rows = static_cast<int>(std::ceil((top + Rb) / h)) + 1;
  std::vector<dem2d::Vec2> cand;
  std::vector<double> cand_r;
  for (int j = 0; j < t.rows; ++j)
    for (int i = 0; i < t.cols; ++i)
      for (std::size_t k : patch) {
        const dem2d::Vec2 p{x[k].x + t.half - Rb + i * w, x[k].y - t.y0 - Rb + j * h};
        if (p.y > top || dem2d::norm(p) + r[k] > Rb) continue;
        cand.push_back(p);
        cand_r.push_back(r[k]);
      }
  // Keep-first at the seams.
  const bench::PointGrid grid(cand, 2.0 * kRadiusMax);
  std::vector<char> kept(cand.size(), 0);
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < cand.size(); ++i) {
    bool clash = false;
    grid.neighbours(cand[i], [&](std::size_t u) {
      if (!clash && kept[u] && dem2d::norm(cand[i] - cand[u]) < cand_r[i] + cand_r[u] - allowed)
        clash = true;
    });
    if (!clash) {
      kept[i] = 1;
      order.push_back(i);
    }
  }
  std::sort(order.begin(), order.end(), [&](std::size_t p, std::size_t q) {
    return cand[p].y != cand[q].y ? cand[p].y < cand[q].y : cand[p].x < cand[q].x;
  });
  if (static_cast<std::int64_t>(order.size()) < n_target)
    throw std::runtime_error("partition: tiling gave only " + std::to_string(order.size()) +
                             " particles");
  t.patch = patch.size();
  t.candidates = cand.size();
  t.kept = order.size();
  order.resize(static_cast<std::size_t>(n_target));
  for (std::size_t i : order) {
    t.pos.push_back(cand[i]);
    t.radius.push_back(cand_r[i]);
  }
  return t;
}

struct Charge {
  std::string name;
  double drum_radius = 0.0;
  std::vector<Vec2> x;
  std::vector<double> r;
  std::size_t size() const { return x.size(); }
};

// Charges (b) and (c): tiles of a patch of charge (a) (header).
Charge tile_charge(const Charge& a, std::int64_t n_target, const std::string& name) {
  const double R = a.drum_radius, scale = std::sqrt(static_cast<double>(n_target) / a.size());
  Charge b;
  b.name = name;
  b.drum_radius = R * scale;
  // Seams may overlap by 0.1 mm: no dynamics here, only where the particles are.
  Tiling t = tile(a.x, a.r, R, b.drum_radius, n_target, 1.0e-4);
  b.x = std::move(t.pos);
  b.r = std::move(t.radius);
  std::printf(
      "%s tiled in a drum of radius %.3f m: patch |x| < %.3f m, y in [%.3f, %.3f) m (%zu "
      "particles, of %zu), %d x %d copies, %zu candidates, %zu after the seam overlaps; surface "
      "y = %.3f m (%.3f x the 30k surface %.3f m = %.3f m)\n",
      name.c_str(), b.drum_radius, t.half, t.y0, t.y1, t.patch, a.size(), t.cols, t.rows,
      t.candidates, t.kept, b.x.back().y, scale, t.surface, t.surface * scale);
  return b;
}

// Contacts per particle: pairs with |x_i - x_j| < r_i + r_j + skin.
std::vector<int> contacts_per_particle(const Charge& c, std::int64_t& pairs) {
  const bench::PointGrid grid(c.x, 2.0 * kRadiusMax + kSkin);
  std::vector<int> count(c.size(), 0);
  pairs = 0;
  for (std::size_t i = 0; i < c.size(); ++i)
    grid.neighbours(c.x[i], [&](std::size_t u) {
      if (u <= i) return;
      if (norm(c.x[i] - c.x[u]) < c.r[i] + c.r[u] + kSkin) {
        ++count[i];
        ++count[u];
        ++pairs;
      }
    });
  return count;
}

// Angles and radii about the centre (theta in [0, 2 pi) as in sector_of).
struct Polar {
  std::vector<double> theta, rho;
};
Polar polar_of(const Charge& c) {
  Polar p;
  for (Vec2 x : c.x) {
    double a = std::atan2(x.y, x.x);
    if (a < 0.0) a += dem2d::kTwoPi;
    p.theta.push_back(a);
    p.rho.push_back(norm(x));
  }
  return p;
}

// Sector index range [lo, hi] (unreduced) covering the angles within the halo of a particle.
bool halo_window(double theta, double rho, int n, long& lo, long& hi) {
  if (rho <= kHalo) return false;  // every sector
  const double delta = std::asin(kHalo / rho), width = dem2d::kTwoPi / n;
  lo = static_cast<long>(std::floor((theta - delta) / width)) - 1;
  hi = static_cast<long>(std::floor((theta + delta) / width)) + 1;
  return hi - lo + 1 < n;
}

double distance_to_ray(Vec2 p, double angle) {
  const Vec2 u{std::cos(angle), std::sin(angle)};
  return dot(u, p) > 0.0 ? std::abs(cross(u, p)) : norm(p);
}

// boundary[s]: particles within the halo of the ray between sectors s and s + 1.
std::vector<double> boundary_weights(const Charge& c, const Polar& pol, int n) {
  std::vector<double> b(static_cast<std::size_t>(n), 0.0);
  const double width = dem2d::kTwoPi / n;
  for (std::size_t i = 0; i < c.size(); ++i) {
    long lo = 0, hi = n - 1;
    if (!halo_window(pol.theta[i], pol.rho[i], n, lo, hi)) {
      lo = 0;
      hi = n - 1;
    }
    for (long k = lo; k <= hi; ++k) {
      const long ray = ((k % n) + n) % n;  // boundary ray `ray` lies between ray - 1 and ray
      if (distance_to_ray(c.x[i], static_cast<double>(ray) * width) < kHalo)
        b[static_cast<std::size_t>((ray - 1 + n) % n)] += 1.0;
    }
  }
  return b;
}

struct Halo {
  std::vector<std::int64_t> owned, ghosts;
};

Halo halo_of(const Charge& c, const Polar& pol, const std::vector<int>& sector,
             const SectorPartition& p) {
  const int n = p.n_sectors, np = p.parts();
  Halo h;
  h.owned.assign(static_cast<std::size_t>(np), 0);
  h.ghosts.assign(static_cast<std::size_t>(np), 0);
  std::vector<int> cand;
  for (std::size_t i = 0; i < c.size(); ++i) {
    const int own = p.owner[static_cast<std::size_t>(sector[i])];
    ++h.owned[static_cast<std::size_t>(own)];
    cand.clear();
    long lo = 0, hi = 0;
    if (halo_window(pol.theta[i], pol.rho[i], n, lo, hi)) {
      for (long k = lo; k <= hi; ++k) {
        const int q = p.owner[static_cast<std::size_t>(((k % n) + n) % n)];
        if (q != own && std::find(cand.begin(), cand.end(), q) == cand.end()) cand.push_back(q);
      }
    } else {
      for (int q = 0; q < np; ++q)
        if (q != own) cand.push_back(q);
    }
    for (int q : cand)
      if (dem2d::distance_to_part(c.x[i], {0.0, 0.0}, p, q) < kHalo)
        ++h.ghosts[static_cast<std::size_t>(q)];
  }
  return h;
}

struct Row {
  std::string charge, work, method, detail;
  std::int64_t n_particles = 0;
  int nranks = 0, spr = 0;
  double imbalance = 0.0, ghosts_mean = 0.0, ghost_ratio = 0.0, ms = 0.0;
  std::int64_t ghosts_max = 0, owned_min = 0, owned_max = 0;
  double rank_ratio_max = 0.0;   // max over ranks owning particles of ghosts / owned
  int ranks_over_limit = 0;      // ranks owning particles with ghosts > kHaloLimit x owned
  double wedge_min_deg = 0.0;    // narrowest arc of a rank owning particles, degrees
  double wedge_min_shell = 0.0;  // its width at the drum shell, m
};

// The halo figures of a row from the per-rank owned and ghost counts.
void fill_halo(Row& r, const Halo& h, const SectorPartition& p, double drum_radius) {
  std::int64_t total_ghosts = 0;
  for (std::int64_t g : h.ghosts) total_ghosts += g;
  r.ghosts_mean = static_cast<double>(total_ghosts) / r.nranks;
  r.ghosts_max = *std::max_element(h.ghosts.begin(), h.ghosts.end());
  r.ghost_ratio = static_cast<double>(total_ghosts) / static_cast<double>(r.n_particles);
  r.owned_min = *std::min_element(h.owned.begin(), h.owned.end());
  r.owned_max = *std::max_element(h.owned.begin(), h.owned.end());
  int narrowest = p.n_sectors;
  for (std::size_t k = 0; k < h.owned.size(); ++k) {
    const auto owned = static_cast<double>(h.owned[k]), ghosts = static_cast<double>(h.ghosts[k]);
    if (h.owned[k] == 0) continue;
    if (ghosts > kHaloLimit * owned) ++r.ranks_over_limit;
    r.rank_ratio_max = std::max(r.rank_ratio_max, ghosts / owned);
    narrowest = std::min(narrowest, p.arcs[k].count);
  }
  const double angle = narrowest * dem2d::kTwoPi / p.n_sectors;
  r.wedge_min_deg = angle * 360.0 / dem2d::kTwoPi;
  r.wedge_min_shell = angle * drum_radius;
}

struct Options {
  bool plot = true;
  std::string results = DEM2D_SOURCE_DIR "/bench/results";
};

Options parse(int argc, char** argv) {
  Options o;
  for (int k = 1; k < argc; ++k) {
    const std::string a = argv[k];
    if (a == "--no-plot") {
      o.plot = false;
    } else if (a == "--results" && k + 1 < argc) {
      o.results = argv[++k];
    } else {
      std::fprintf(stderr, "usage: partition [--no-plot] [--results DIR]\n");
      std::exit(a == "--help" || a == "-h" ? 0 : 2);
    }
  }
  return o;
}

const Row* find(const std::vector<Row>& rows, const std::string& charge, const std::string& work,
                int nranks, int spr, const std::string& method) {
  for (const Row& r : rows)
    if (r.charge == charge && r.work == work && r.nranks == nranks && r.spr == spr &&
        r.method == method)
      return &r;
  return nullptr;
}

struct Case {
  const Charge* charge;
  std::string work;
  std::vector<double> weight;  // per particle
};

// The table: imbalance at 16, 32 and 64 sectors per rank, the fewest sectors per rank
// reaching 5 %, and the halo at the default 32.
void print_table(const std::vector<Case>& cases, const std::vector<Row>& rows) {
  std::printf(
      "%-4s %-9s %5s | %7s %7s %7s %7s %7s | %5s | %8s %7s %6s %7s %4s %6s | %8s %6s %7s | %s\n",
      "N", "work", "ranks", "metis16", "equal16", "metis32", "metis64", "equal64", "spr5%",
      "ghosts", "max", "g/own", "rankmax", ">50%", "wedge", "eq ghost", "g/own", "rankmax",
      "metis32 method");
  for (const Case& cs : cases) {
    for (int nranks : kRanks) {
      const std::string& cn = cs.charge->name;
      const Row* m16 = find(rows, cn, cs.work, nranks, 16, "metis");
      const Row* e16 = find(rows, cn, cs.work, nranks, 16, "equal-angle");
      const Row* m32 = find(rows, cn, cs.work, nranks, kDefaultSpr, "metis");
      const Row* e32 = find(rows, cn, cs.work, nranks, kDefaultSpr, "equal-angle");
      const Row* m64 = find(rows, cn, cs.work, nranks, 64, "metis");
      const Row* e64 = find(rows, cn, cs.work, nranks, 64, "equal-angle");
      char more[16];  // (">" + std::to_string: a false -Wrestrict in GCC 12)
      std::snprintf(more, sizeof more, ">%d", kSectorsPerRank.back());
      std::string spr5 = more;
      for (int spr : kSectorsPerRank) {
        const Row* r = find(rows, cn, cs.work, nranks, spr, "metis");
        if (r && r->imbalance <= kTarget) {
          spr5 = std::to_string(spr);
          break;
        }
      }
      std::printf(
          "%-4s %-9s %5d | %7.4f %7.4f %7.4f %7.4f %7.4f | %5s | %8.1f %7lld %6.3f %7.3f %4d "
          "%6.1f | %8.1f %6.3f %7.3f | %s\n",
          cn.c_str(), cs.work.c_str(), nranks, m16->imbalance, e16->imbalance, m32->imbalance,
          m64->imbalance, e64->imbalance, spr5.c_str(), m32->ghosts_mean,
          static_cast<long long>(m32->ghosts_max), m32->ghost_ratio, m32->rank_ratio_max,
          m32->ranks_over_limit, 1e3 * m32->wedge_min_shell, e32->ghosts_mean, e32->ghost_ratio,
          e32->rank_ratio_max, m32->detail.c_str());
    }
  }
  std::printf(
      "   metisS / equalS: imbalance (max rank work / mean) at S sectors per rank; spr5%%: fewest "
      "sectors per rank\n"
      "   (of 16 24 32 48 64 96 128) with METIS imbalance <= %.2f. At %d sectors per rank (the "
      "default): ghosts, max:\n"
      "   mean and max ghosts per rank; g/own: all ghosts / N; rankmax: the largest ghosts / "
      "owned of one rank;\n"
      "   >50%%: ranks holding more ghosts than half their owned particles; wedge: the narrowest "
      "rank's arc at the\n"
      "   shell, mm (halo width %.1f mm); eq ghost, g/own, rankmax: the same for equal angles\n",
      kTarget, kDefaultSpr, 1e3 * kHalo);
}

// The rank counts from which the halo passes half the owned particles (32 sectors per rank).
void print_halo_limits(const std::vector<Case>& cases, const std::vector<Row>& rows) {
  std::printf("\nhalo past %.0f %% of the owned particles, at %d sectors per rank:\n",
              100.0 * kHaloLimit, kDefaultSpr);
  for (const Case& cs : cases) {
    if (cs.work != "particles") continue;
    for (const std::string method : {"metis", "equal-angle"}) {
      std::string all = "never", one = "never";
      for (auto k = kRanks.rbegin(); k != kRanks.rend(); ++k) {
        const Row* r = find(rows, cs.charge->name, cs.work, *k, kDefaultSpr, method);
        if (r->ghost_ratio > kHaloLimit) all = "from " + std::to_string(*k) + " ranks";
        if (r->rank_ratio_max > kHaloLimit) one = "from " + std::to_string(*k) + " ranks";
      }
      std::printf("   %-4s %-11s all ghosts / N: %-16s the worst rank: %s\n",
                  cs.charge->name.c_str(), method.c_str(), all.c_str(), one.c_str());
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  const auto t_start = Clock::now();
  const std::string cache = opt.results + "/cache/settled_drum_30000.csv";
  Charge small;
  small.name = "30k";
  small.drum_radius = kRefDrum;
  const std::optional<bench::Packing> settled =
      bench::cached_packing(30000, opt.results + "/cache");
  if (!settled) {
    std::fprintf(stderr,
                 "partition: %s is missing: make it with\n  build/bench/throughput --particles "
                 "30000\n(settles the 30 000-sphere charge, ~6 min, and caches it)\n",
                 cache.c_str());
    return 1;
  }
  small.x = settled->pos;
  small.r = settled->radius;
  std::printf(
      "== partition: angular sectors, METIS (+refinement) vs equal angles; halo width "
      "h = 2 r_max + skin = %.1f mm\n",
      1e3 * kHalo);
  std::printf("(a) %zu particles from %s\n", small.size(), cache.c_str());
  auto t_tile = Clock::now();
  const Charge big = tile_charge(small, 300000, "300k");
  std::printf("    (%.2f s)\n", seconds_since(t_tile));
  t_tile = Clock::now();
  const Charge huge = tile_charge(small, 1000000, "1M");
  std::printf("    (%.2f s)\n", seconds_since(t_tile));

  std::int64_t pairs = 0;
  const std::vector<int> contacts = contacts_per_particle(small, pairs);
  std::printf("(a) contact pairs within r_i + r_j + %.1f mm: %lld (%.2f per particle)\n\n",
              1e3 * kSkin, static_cast<long long>(pairs),
              2.0 * static_cast<double>(pairs) / static_cast<double>(small.size()));

  std::vector<Case> cases;
  cases.push_back({&small, "particles", std::vector<double>(small.size(), 1.0)});
  {
    std::vector<double> w(small.size());
    for (std::size_t i = 0; i < w.size(); ++i) w[i] = 0.5 * contacts[i];
    cases.push_back({&small, "contacts", w});
  }
  cases.push_back({&big, "particles", std::vector<double>(big.size(), 1.0)});
  cases.push_back({&huge, "particles", std::vector<double>(huge.size(), 1.0)});

  std::vector<Row> rows;
  for (const Case& cs : cases) {
    const Charge& c = *cs.charge;
    const Polar pol = polar_of(c);
    const auto t_case = Clock::now();
    for (int spr : kSectorsPerRank) {
      for (int nranks : kRanks) {
        const int n = spr * nranks;
        std::vector<int> sector(c.size());
        std::vector<double> work(static_cast<std::size_t>(n), 0.0);
        for (std::size_t i = 0; i < c.size(); ++i) {
          sector[i] = dem2d::sector_of(c.x[i], {0.0, 0.0}, n);
          work[static_cast<std::size_t>(sector[i])] += cs.weight[i];
        }
        const std::vector<double> bw = boundary_weights(c, pol, n);
        for (const std::string method : {"metis", "equal-angle"}) {
          const auto t0 = Clock::now();
          const SectorPartition p = method == "metis" ? dem2d::partition_metis(work, bw, nranks)
                                                      : dem2d::partition_equal_angle(n, nranks);
          const double ms = 1e3 * seconds_since(t0);
          if (!dem2d::is_valid(p)) {
            std::fprintf(stderr, "partition: invalid partition (%s)\n", p.method.c_str());
            return 1;
          }
          const Halo h = halo_of(c, pol, sector, p);
          Row r;
          r.charge = c.name;
          r.work = cs.work;
          r.method = method;
          r.detail = p.method;
          r.n_particles = static_cast<std::int64_t>(c.size());
          r.nranks = nranks;
          r.spr = spr;
          r.imbalance = dem2d::imbalance(work, p);
          r.ms = ms;
          fill_halo(r, h, p, c.drum_radius);
          rows.push_back(r);
        }
      }
    }
    std::printf("%s, %s: %zu partitions in %.1f s\n", c.name.c_str(), cs.work.c_str(),
                2 * kSectorsPerRank.size() * kRanks.size(), seconds_since(t_case));
    std::fflush(stdout);
  }
  std::printf("\n");

  print_table(cases, rows);
  print_halo_limits(cases, rows);

  const std::string csv = opt.results + "/partition.csv";
  std::filesystem::create_directories(opt.results);
  std::ofstream out(csv);
  out << "charge,n_particles,work,nranks,sectors_per_rank,n_sectors,method,method_detail,"
         "imbalance,owned_min,owned_max,ghosts_mean,ghosts_max,ghost_ratio,partition_ms,"
         "halo_width,rank_ghost_ratio_max,ranks_halo_over_half,wedge_min_deg,wedge_min_shell\n";
  char buf[512];
  for (const Row& r : rows) {
    std::snprintf(buf, sizeof buf,
                  "%s,%lld,%s,%d,%d,%d,%s,\"%s\",%.6f,%lld,%lld,%.3f,%lld,%.6f,%.3f,%.4f,%.6f,%d,"
                  "%.5f,%.5f\n",
                  r.charge.c_str(), static_cast<long long>(r.n_particles), r.work.c_str(), r.nranks,
                  r.spr, r.nranks * r.spr, r.method.c_str(), r.detail.c_str(), r.imbalance,
                  static_cast<long long>(r.owned_min), static_cast<long long>(r.owned_max),
                  r.ghosts_mean, static_cast<long long>(r.ghosts_max), r.ghost_ratio, r.ms, kHalo,
                  r.rank_ratio_max, r.ranks_over_limit, r.wedge_min_deg, r.wedge_min_shell);
    out << buf;
  }
  out.close();
  if (!out) {
    std::fprintf(stderr, "partition: cannot write %s\n", csv.c_str());
    return 1;
  }
  std::printf("\nwrote %s (%zu rows); %.1f s\n", csv.c_str(), rows.size(), seconds_since(t_start));
  std::fflush(stdout);
  if (opt.plot) {
    const std::string png = opt.results + "/partition.png";
    const std::string cmd = "/usr/bin/python3 " DEM2D_SOURCE_DIR "/post/plot_partition.py '" + csv +
                            "' -o '" + png + "'";
    if (std::system(cmd.c_str()) != 0) std::printf("partition: the plot script failed\n");
  }
  return 0;
}
