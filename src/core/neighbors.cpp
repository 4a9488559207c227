#include "core/neighbors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace dem2d {

namespace {

// Carry histories (`width` values per contact) from `old` (sorted keys) to `fresh` (sorted
// keys) by key equality; new contacts start at zero.
template <class KeyOld, class KeyNew>
void merge_history(std::size_t width, std::size_t n_old, KeyOld key_old,
                   const Array<double>& hist_old, std::size_t n_new, KeyNew key_new,
                   Array<double>& hist_new) {
  hist_new.assign(n_new * width, 0.0);
  if (width == 0) return;
  std::size_t a = 0;
  for (std::size_t b = 0; b < n_new && a < n_old; ++b) {
    const auto kb = key_new(b);
    while (a < n_old && key_old(a) < kb) ++a;
    if (a < n_old && key_old(a) == kb)
      std::copy_n(&hist_old[a * width], width, &hist_new[b * width]);
  }
}

}  // namespace

void NeighborSearch::build(const ParticleStore& p, const Walls& walls, double skin, PairList& pairs,
                           WallPairList& wall_pairs) {
  ++builds_;
  // Indices in id order (the identity when the store is kept sorted by id).
  const std::size_t n = p.size();
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), 0);
  if (!std::is_sorted(p.id.data(), p.id.data() + n))
    std::sort(order_.begin(), order_.end(), [&](int a, int b) { return p.id[a] < p.id[b]; });
  build_particle_pairs(p, skin, pairs);
  build_wall_pairs(p, walls, skin, wall_pairs);
}

// Counting sort of the particles (owned and ghosts) into a grid of cells of side at least the
// largest reach 2 r_max + skin; sets nx_, ny_, cell_start_, cell_items_, cell_of_.
void NeighborSearch::bin_particles(const ParticleStore& p, double skin) {
  const std::size_t n = p.size();
  double r_max = 0.0;
  Vec2 lo{std::numeric_limits<double>::max(), std::numeric_limits<double>::max()};
  Vec2 hi{-lo.x, -lo.y};
  for (std::size_t k = 0; k < n; ++k) {
    r_max = std::max(r_max, p.radius[k]);
    lo = {std::min(lo.x, p.pos[k].x), std::min(lo.y, p.pos[k].y)};
    hi = {std::max(hi.x, p.pos[k].x), std::max(hi.y, p.pos[k].y)};
  }
  // Cell side: the largest reach, enlarged if the box would need far more cells than particles.
  double h = 2.0 * r_max + skin;
  const double area = std::max(hi.x - lo.x, h) * std::max(hi.y - lo.y, h);
  const double max_cells = 4.0 * static_cast<double>(n) + 1024.0;
  if (area / (h * h) > max_cells) h = std::sqrt(area / max_cells);
  nx_ = static_cast<int>((hi.x - lo.x) / h) + 1;
  ny_ = static_cast<int>((hi.y - lo.y) / h) + 1;
  const double inv_h = 1.0 / h;
  cell_start_.assign(static_cast<std::size_t>(nx_) * ny_ + 1, 0);
  cell_of_.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    // A non-finite position (a run blowing up: the stability check reports it) goes to cell 0
    // rather than to an undefined cell index.
    const double fx = (p.pos[k].x - lo.x) * inv_h, fy = (p.pos[k].y - lo.y) * inv_h;
    const int cx = std::isfinite(fx) ? std::min(nx_ - 1, static_cast<int>(fx)) : 0;
    const int cy = std::isfinite(fy) ? std::min(ny_ - 1, static_cast<int>(fy)) : 0;
    cell_of_[k] = cy * nx_ + cx;
    ++cell_start_[cell_of_[k] + 1];
  }
  std::partial_sum(cell_start_.begin(), cell_start_.end(), cell_start_.begin());
  cell_items_.resize(n);
  std::vector<std::int32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t k = 0; k < n; ++k) cell_items_[fill[cell_of_[k]]++] = static_cast<int>(k);
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
  const int nx = nx_, ny = ny_;
  const std::size_t n_owned = p.n_owned();
  fresh.i.reserve(3 * n);
  fresh.j.reserve(3 * n);
  for (const std::int32_t i : order_) {
    const std::int64_t id_i = p.id[i];
    const Vec2 xi = p.pos[i];
    const double ri = p.radius[i];
    const int cx = cell_of_[i] % nx, cy = cell_of_[i] / nx;
    scratch_.clear();
    for (int y = std::max(0, cy - 1); y <= std::min(ny - 1, cy + 1); ++y) {
      for (int x = std::max(0, cx - 1); x <= std::min(nx - 1, cx + 1); ++x) {
        const int c = y * nx + x;
        for (int s = cell_start_[c]; s < cell_start_[c + 1]; ++s) {
          const std::int32_t j = cell_items_[s];
          if (p.id[j] <= id_i) continue;
          if (static_cast<std::size_t>(i) >= n_owned && static_cast<std::size_t>(j) >= n_owned)
            continue;  // ghost-ghost pairs belong to other ranks
          const double reach = ri + p.radius[j] + skin;
          if (norm2(p.pos[j] - xi) < reach * reach) scratch_.push_back(j);
        }
      }
    }
    std::sort(scratch_.begin(), scratch_.end(),
              [&](std::int32_t a, std::int32_t b) { return p.id[a] < p.id[b]; });
    for (const std::int32_t j : scratch_) {
      fresh.i.push_back(i);
      fresh.j.push_back(j);
      fresh.id_i.push_back(id_i);
      fresh.id_j.push_back(p.id[j]);
    }
  }
  merge_history(
      out.width, out.size(),
      [&](std::size_t k) {
        return std::pair{out.id_i[k], out.id_j[k]};
      },
      out.history, fresh.size(),
      [&](std::size_t k) {
        return std::pair{fresh.id_i[k], fresh.id_j[k]};
      },
      fresh.history);
  fresh.trial = fresh.history;
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
      if (walls.geometry(e, x, r).delta > -skin) {
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
      out.history, fresh.size(),
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
