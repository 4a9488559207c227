#include "core/contact/neighbors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "core/shape/disc.hpp"

namespace dem2d {

namespace {

// Carry histories (`width` values per contact) from `old` to `fresh` by key equality; new
// contacts start at zero. key_old(a) and key_new(b) are sorted; old_entry(a) is where the a-th
// old key's history sits.
template <class KeyOld, class KeyNew, class OldEntry>
void merge_history(std::size_t width, std::size_t n_old, KeyOld key_old, OldEntry old_entry,
                   const Array<double>& hist_old, std::size_t n_new, KeyNew key_new,
                   Array<double>& hist_new) {
  hist_new.assign(n_new * width, 0.0);
  if (width == 0) return;
  std::size_t a = 0;
  for (std::size_t b = 0; b < n_new && a < n_old; ++b) {
    const auto kb = key_new(b);
    while (a < n_old && key_old(a) < kb) ++a;
    if (a < n_old && key_old(a) == kb)
      std::copy_n(&hist_old[old_entry(a) * width], width, &hist_new[b * width]);
  }
}

// Reorder `pl` (built in canonical order) by (lower local index of the pair, canonical order):
// sets key_order, and each owned particle's records (2k as i, 2k + 1 as j) in canonical order,
// which is the order of its partners' ids (core/contact/neighbors.hpp).
void to_storage_order(std::size_t n, std::size_t n_owned, PairList& pl) {
  const std::size_t m = pl.size();
  std::vector<std::int32_t> start(n + 1, 0);
  for (std::size_t k = 0; k < m; ++k) ++start[std::min(pl.i[k], pl.j[k]) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  pl.key_order.resize(m);
  for (std::size_t k = 0; k < m; ++k) pl.key_order[k] = start[std::min(pl.i[k], pl.j[k])]++;
  const auto permute = [&]<class T>(Array<T>& a, std::size_t width) {
    Array<T> out(a.size());
    for (std::size_t k = 0; k < m; ++k)
      std::copy_n(&a[k * width], width, &out[static_cast<std::size_t>(pl.key_order[k]) * width]);
    a.swap(out);
  };
  permute(pl.i, 1);
  permute(pl.j, 1);
  permute(pl.id_i, 1);
  permute(pl.id_j, 1);
  permute(pl.history, pl.width);
  pl.record_start.assign(n_owned + 1, 0);
  const auto owned = [&](std::int32_t q) { return static_cast<std::size_t>(q) < n_owned; };
  for (std::size_t k = 0; k < m; ++k) {
    if (owned(pl.i[k])) ++pl.record_start[pl.i[k] + 1];
    if (owned(pl.j[k])) ++pl.record_start[pl.j[k] + 1];
  }
  std::partial_sum(pl.record_start.begin(), pl.record_start.end(), pl.record_start.begin());
  pl.records.resize(static_cast<std::size_t>(pl.record_start[n_owned]));
  std::vector<std::int32_t> fill(pl.record_start.begin(), pl.record_start.end() - 1);
  for (std::size_t t = 0; t < m; ++t) {
    const std::int32_t k = pl.key_order[t];
    if (owned(pl.i[k])) pl.records[fill[pl.i[k]]++] = 2 * k;
    if (owned(pl.j[k])) pl.records[fill[pl.j[k]]++] = 2 * k + 1;
  }
}

}  // namespace

void NeighborSearch::build(const ParticleStore& p, const Walls& walls, double skin, PairList& pairs,
                           WallPairList& wall_pairs) {
  ++builds_;
  sort_by_id(p);
  build_particle_pairs(p, skin, pairs);
  build_wall_pairs(p, walls, skin, wall_pairs);
}

// Indices in id order: the owned particles' order is kept while the store's layout holds (the
// identity when the store is in id order), the ghosts' (new at every parallel rebuild) merged in.
void NeighborSearch::sort_by_id(const ParticleStore& p) {
  const std::size_t n_owned = p.n_owned(), n = p.size();
  const auto by_id = [&](std::int32_t a, std::int32_t b) { return p.id[a] < p.id[b]; };
  if (layout_ != p.layout() || owned_order_.size() != n_owned) {
    owned_order_.resize(n_owned);
    std::iota(owned_order_.begin(), owned_order_.end(), 0);
    id_ordered_ = std::is_sorted(p.id.data(), p.id.data() + n_owned);
    if (!id_ordered_) std::sort(owned_order_.begin(), owned_order_.end(), by_id);
    layout_ = p.layout();
  }
  order_.resize(n);
  std::copy(owned_order_.begin(), owned_order_.end(), order_.begin());
  if (n == n_owned) return;
  std::iota(order_.begin() + static_cast<std::ptrdiff_t>(n_owned), order_.end(),
            static_cast<std::int32_t>(n_owned));
  std::sort(order_.begin() + static_cast<std::ptrdiff_t>(n_owned), order_.end(), by_id);
  std::inplace_merge(order_.begin(), order_.begin() + static_cast<std::ptrdiff_t>(n_owned),
                     order_.end(), by_id);
}

// Counting sort of the particles (owned and ghosts) into one grid per size level, when levels
// are used (levels_pay; otherwise one level: the plain cell grid). Level l holds the radii in
// (r_max / 2^(l+1), r_max / 2^l] (the last level everything smaller), and its cells have a side
// of at least its largest reach 2 R_l + skin, so a particle finds its partners of level l in the
// few cells within r_i + R_l + skin. With a wide size range a small particle then no longer
// scans cells sized for the largest ones (up to a hundred small particles each at 10:1).
void NeighborSearch::bin_particles(const ParticleStore& p, double skin) {
  const std::size_t n = p.size();
  double r_max = 0.0, r_min = std::numeric_limits<double>::max();
  Vec2 lo{std::numeric_limits<double>::max(), std::numeric_limits<double>::max()};
  Vec2 hi{-lo.x, -lo.y};
  for (std::size_t k = 0; k < n; ++k) {
    r_max = std::max(r_max, p.radius[k]);
    r_min = std::min(r_min, p.radius[k]);
    lo = {std::min(lo.x, p.pos[k].x), std::min(lo.y, p.pos[k].y)};
    hi = {std::max(hi.x, p.pos[k].x), std::max(hi.y, p.pos[k].y)};
  }
  lo_ = lo;
  int n_levels = 1;
  while (levels_mode_ != Levels::kNever && n_levels < kMaxLevels &&
         std::ldexp(r_min, n_levels) < r_max)
    ++n_levels;
  levels_.resize(static_cast<std::size_t>(n_levels));
  level_of_.resize(n);
  for (Level& l : levels_) {
    l.r_max = 0.0;
    l.count = 0;
  }
  for (std::size_t k = 0; k < n; ++k) {
    int l = 0;
    while (l + 1 < n_levels && p.radius[k] <= std::ldexp(r_max, -(l + 1))) ++l;
    level_of_[k] = static_cast<std::int8_t>(l);
    levels_[l].r_max = std::max(levels_[l].r_max, p.radius[k]);
    ++levels_[l].count;
  }
  if (n_levels > 1 && levels_mode_ == Levels::kAuto && !levels_pay(hi - lo, r_max, skin)) {
    levels_.resize(1);
    levels_[0].r_max = r_max;
    levels_[0].count = n;
    std::fill(level_of_.begin(), level_of_.end(), std::int8_t{0});
  }
  for (Level& l : levels_) {
    // Cell side: the level's largest reach, enlarged if the box would need far more cells than
    // the level has particles.
    double h = 2.0 * l.r_max + skin;
    const double area = std::max(hi.x - lo.x, h) * std::max(hi.y - lo.y, h);
    const double max_cells = 4.0 * static_cast<double>(l.count) + 1024.0;
    if (area / (h * h) > max_cells) h = std::sqrt(area / max_cells);
    l.inv_h = 1.0 / h;
    l.nx = static_cast<int>((hi.x - lo.x) / h) + 1;
    l.ny = static_cast<int>((hi.y - lo.y) / h) + 1;
    l.start.assign(static_cast<std::size_t>(l.nx) * l.ny + 1, 0);
  }
  cell_of_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    Level& l = levels_[level_of_[k]];
    const auto [cx, cy] = cell(l, p.pos[k]);
    cell_of_[k] = cy * l.nx + cx;
    ++l.start[cell_of_[k] + 1];
  }
  for (Level& l : levels_) {
    std::partial_sum(l.start.begin(), l.start.end(), l.start.begin());
    l.items.resize(l.count);
    l.fill.assign(l.start.begin(), l.start.end() - 1);
  }
  for (std::size_t k = 0; k < n; ++k) {
    Level& l = levels_[level_of_[k]];
    l.items[l.fill[cell_of_[k]]++] = static_cast<int>(k);
  }
}

// Whether the levels (counts and largest radii set) need fewer cell visits and distance tests
// than one grid sized by r_max: the expected work over the box (particles spread evenly), a
// cell visit counted as one test. Levels pay when the small particles are many (a grinding
// charge: fragments among balls); with as many particles per factor of radius as the small
// ones (log-uniform radii) one grid was cheaper (bench/throughput, ratios section).
bool NeighborSearch::levels_pay(Vec2 box, double r_max, double skin) const {
  const auto cells = [&](double h) { return std::max(box.x, h) * std::max(box.y, h) / (h * h); };
  double n = 0.0;
  for (const Level& l : levels_) n += static_cast<double>(l.count);
  const double h0 = 2.0 * r_max + skin;
  const double single = n * 9.0 * (1.0 + n / cells(h0));
  double levels = 0.0;
  for (const Level& a : levels_) {
    if (a.count == 0) continue;
    for (const Level& b : levels_) {
      if (b.count == 0) continue;
      const double h = 2.0 * b.r_max + skin;
      const double side = std::floor(2.0 * (a.r_max + b.r_max + skin) / h) + 2.0;
      levels += static_cast<double>(a.count) * side * side *
                (1.0 + static_cast<double>(b.count) / cells(h));
    }
  }
  return levels < kLevelsGain * single;
}

// The cell of level l that holds x. A non-finite position (a run blowing up: the stability
// check reports it) goes to cell 0 rather than to an undefined cell index.
std::pair<int, int> NeighborSearch::cell(const Level& l, Vec2 x) const {
  const double fx = (x.x - lo_.x) * l.inv_h, fy = (x.y - lo_.y) * l.inv_h;
  const int cx = std::isfinite(fx) ? std::clamp(static_cast<int>(fx), 0, l.nx - 1) : 0;
  const int cy = std::isfinite(fy) ? std::clamp(static_cast<int>(fy), 0, l.ny - 1) : 0;
  return {cx, cy};
}

// The partners j of particle i with a larger id within r_i + r_j + skin (not ghost-ghost), in
// scratch_, in id order.
void NeighborSearch::find_partners(const ParticleStore& p, std::int32_t i, double skin) {
  const std::int64_t id_i = p.id[i];
  const Vec2 xi = p.pos[i];
  const double ri = p.radius[i];
  const bool ghost_i = static_cast<std::size_t>(i) >= p.n_owned();
  scratch_.clear();
  for (const Level& l : levels_) {
    if (l.count == 0) continue;
    // Cells within r_i + R_l + skin of x_i (the own cell and its 8 neighbours on one level).
    const double reach_l = ri + l.r_max + skin;
    const auto [x0, y0] = cell(l, {xi.x - reach_l, xi.y - reach_l});
    const auto [x1, y1] = cell(l, {xi.x + reach_l, xi.y + reach_l});
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const int c = y * l.nx + x;
        for (int s = l.start[c]; s < l.start[c + 1]; ++s) {
          const std::int32_t j = l.items[s];
          if (p.id[j] <= id_i) continue;
          if (ghost_i && static_cast<std::size_t>(j) >= p.n_owned())
            continue;  // ghost-ghost pairs belong to other ranks
          const double reach = ri + p.radius[j] + skin;
          if (norm2(p.pos[j] - xi) < reach * reach) scratch_.push_back(j);
        }
      }
    }
  }
  std::sort(scratch_.begin(), scratch_.end(),
            [&](std::int32_t a, std::int32_t b) { return p.id[a] < p.id[b]; });
}

void NeighborSearch::build_particle_pairs(const ParticleStore& p, double skin, PairList& out) {
  const std::size_t n = p.size();
  PairList fresh;
  fresh.width = out.width;
  if (n == 0) {
    out = std::move(fresh);
    return;
  }
  bin_particles(p, skin);
  fresh.i.reserve(3 * n);
  fresh.j.reserve(3 * n);
  std::size_t far = 0;
  for (const std::int32_t i : order_) {
    find_partners(p, i, skin);
    const std::int64_t id_i = p.id[i];
    for (const std::int32_t j : scratch_) {
      far += std::abs(j - i) > kNear ? 1 : 0;
      fresh.i.push_back(i);
      fresh.j.push_back(j);
      fresh.id_i.push_back(id_i);
      fresh.id_j.push_back(p.id[j]);
    }
  }
  far_fraction_ = fresh.size() ? static_cast<double>(far) / static_cast<double>(fresh.size()) : 0.0;
  merge_history(
      out.width, out.size(),
      [&](std::size_t t) {
        const std::size_t k = out.entry(t);
        return std::pair{out.id_i[k], out.id_j[k]};
      },
      [&](std::size_t t) { return out.entry(t); }, out.history, fresh.size(),
      [&](std::size_t k) {
        return std::pair{fresh.id_i[k], fresh.id_j[k]};
      },
      fresh.history);
  if (!id_ordered_) to_storage_order(n, p.n_owned(), fresh);
  if (pair_trials_) fresh.trial = fresh.history;
  out = std::move(fresh);
}

void NeighborSearch::build_wall_pairs(const ParticleStore& p, const Walls& walls, double skin,
                                      WallPairList& out) {
  WallPairList fresh;
  fresh.width = out.width;
  const auto& elements = walls.elements();
  const int n_el = static_cast<int>(elements.size());
  // Closest approach of any drum segment to the drum centre: particles well inside skip them.
  double drum_clear = std::numeric_limits<double>::max();
  Vec2 drum_center{};
  if (walls.has_drum()) {
    const WallBody& b = walls.bodies()[walls.drum_body()];
    drum_center = b.center + b.offset;
    for (const WallElement& e : elements) {
      if (e.body != walls.drum_body() || e.kind != WallKind::kSegment) continue;
      const Vec2 ab = e.b_ref - e.a_ref;
      const double s = std::clamp(-dot(e.a_ref, ab) / norm2(ab), 0.0, 1.0);
      drum_clear = std::min(drum_clear, norm(e.a_ref + s * ab));
    }
  }
  for (const std::int32_t i : order_) {
    if (static_cast<std::size_t>(i) >= p.n_owned()) continue;
    const Vec2 x = p.pos[i];
    const double r = p.radius[i];
    const bool inside_clear = walls.has_drum() && norm(x - drum_center) + r + skin < drum_clear;
    for (int e = 0; e < n_el; ++e) {
      if (inside_clear && elements[e].body == walls.drum_body() &&
          elements[e].kind == WallKind::kSegment)
        continue;
      if (Disc::wall(walls, e, x, r).delta > -skin) {
        fresh.particle.push_back(i);
        fresh.element.push_back(e);
        fresh.id.push_back(p.id[i]);
      }
    }
  }
  merge_history(
      out.width, out.size(),
      [&](std::size_t k) {
        return std::pair{out.id[k], out.element[k]};
      },
      [](std::size_t k) { return k; }, out.history, fresh.size(),
      [&](std::size_t k) {
        return std::pair{fresh.id[k], fresh.element[k]};
      },
      fresh.history);
  fresh.trial = fresh.history;
  out = std::move(fresh);
}

std::vector<std::pair<std::int64_t, std::int64_t>> NeighborSearch::brute_force_pairs(
    const ParticleStore& p, double cutoff_extra) {
  std::vector<std::pair<std::int64_t, std::int64_t>> result;
  for (std::size_t a = 0; a < p.size(); ++a)
    for (std::size_t b = 0; b < p.size(); ++b) {
      if (p.id[a] >= p.id[b]) continue;
      const double reach = p.radius[a] + p.radius[b] + cutoff_extra;
      if (norm2(p.pos[b] - p.pos[a]) < reach * reach) result.emplace_back(p.id[a], p.id[b]);
    }
  std::sort(result.begin(), result.end());
  return result;
}

}  // namespace dem2d
