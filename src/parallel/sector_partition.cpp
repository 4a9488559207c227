// Angular-sector partition: see sector_partition.hpp for every formula and decision.
#include "parallel/sector_partition.hpp"

#include <metis.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <utility>

namespace dem2d {

namespace {

constexpr double kVertexScale = 1.0e6;  // METIS vertex weights sum to about this
constexpr double kEdgeScale = 1000.0;   // the heaviest boundary gets this edge weight
constexpr idx_t kMetisSeed = 20111;
constexpr idx_t kMetisUfactor = 20;  // max part weight <= (1 + 20 / 1000) x mean
constexpr idx_t kMetisNcuts = 4;
constexpr int kMetisMinSectorsPerPart = 4;
constexpr double kMetisMaxSectorShare = 0.5;  // of the mean part work
constexpr double kMetisAccept = 1.03;         // keep METIS if max/mean <= this (or <= the optimum)
constexpr double kRelativeSlack = 1.0e-12;

void check_parts(int n_sectors, int nparts) {
  if (n_sectors < 1) throw std::invalid_argument("sector partition: n_sectors must be >= 1");
  if (nparts < 1 || nparts > n_sectors)
    throw std::invalid_argument("sector partition: nparts = " + std::to_string(nparts) +
                                " must be in [1, n_sectors = " + std::to_string(n_sectors) +
                                "] (every part needs at least one sector)");
}

void check_weights(std::span<const double> w, std::size_t n, const char* what) {
  if (w.size() != n)
    throw std::invalid_argument(std::string("sector partition: ") + what + " has " +
                                std::to_string(w.size()) + " entries, expected " +
                                std::to_string(n));
  for (double v : w)
    if (!std::isfinite(v) || v < 0.0)
      throw std::invalid_argument(std::string("sector partition: ") + what +
                                  " must be finite and >= 0");
}

// Work of one arc, summed in sector order.
double arc_work(std::span<const double> w, Arc a) {
  const int n = static_cast<int>(w.size());
  double sum = 0.0;
  for (int k = 0; k < a.count; ++k) sum += w[static_cast<std::size_t>((a.first + k) % n)];
  return sum;
}

// Canonical partition from arcs that tile the ring (any order, first in any range).
SectorPartition from_arcs(int n, std::vector<Arc> arcs, std::string method) {
  for (Arc& a : arcs) a.first = ((a.first % n) + n) % n;
  std::sort(arcs.begin(), arcs.end(), [](Arc a, Arc b) { return a.first < b.first; });
  SectorPartition p;
  p.n_sectors = n;
  p.owner.assign(static_cast<std::size_t>(n), -1);
  for (std::size_t k = 0; k < arcs.size(); ++k)
    for (int j = 0; j < arcs[k].count; ++j)
      p.owner[static_cast<std::size_t>((arcs[k].first + j) % n)] = static_cast<int>(k);
  p.arcs = std::move(arcs);
  p.method = std::move(method);
  return p;
}

// Prefix sums over the doubled ring: P[i] = w[0] + ... + w[(i - 1) mod n], i = 0 .. 2n.
class RingPrefix {
 public:
  explicit RingPrefix(std::span<const double> w) : n_(static_cast<int>(w.size())) {
    p_.resize(2 * w.size() + 1, 0.0);
    for (std::size_t i = 0; i < 2 * w.size(); ++i) p_[i + 1] = p_[i] + w[i % w.size()];
  }
  // Largest e in [pos, limit] with P[e] - P[pos] <= bound (P is non-decreasing).
  int greedy_end(int pos, int limit, double bound) const {
    int lo = pos, hi = limit;
    while (lo < hi) {
      const int mid = lo + (hi - lo + 1) / 2;
      if (p_[static_cast<std::size_t>(mid)] - p_[static_cast<std::size_t>(pos)] <= bound)
        lo = mid;
      else
        hi = mid - 1;
    }
    return lo;
  }
  // Smallest start s in 0 .. g (g = greedy_end(0, n, bound)) from which <= nparts greedy arcs
  // of work <= bound close the ring; -1 if none. next[i] = greedy_end(i, 2n, bound) for
  // i = 0 .. 2n by two pointers (next is non-decreasing in i); jump tables next^(2^k) give the
  // position after nparts arcs from each start in O(log nparts). Capping each arc at s + n
  // changes nothing: the walk closes the ring iff the uncapped walk reaches s + n.
  int feasible_start(double bound, int nparts) const {
    const int g = greedy_end(0, n_, bound);
    if (g == n_) return 0;
    const auto m = static_cast<std::size_t>(2 * n_ + 1);
    jump_.resize(1);
    jump_[0].resize(m);
    std::size_t e = 0;
    for (std::size_t i = 0; i < m; ++i) {
      e = std::max(e, i);
      while (e + 1 < m && p_[e + 1] - p_[i] <= bound) ++e;
      jump_[0][i] = static_cast<int>(e);
    }
    int levels = 1;
    while ((1 << levels) <= nparts) ++levels;
    for (int k = 1; k < levels; ++k) {
      jump_.emplace_back(m);
      const std::vector<int>& prev = jump_[static_cast<std::size_t>(k - 1)];
      std::vector<int>& cur = jump_[static_cast<std::size_t>(k)];
      for (std::size_t i = 0; i < m; ++i) cur[i] = prev[static_cast<std::size_t>(prev[i])];
    }
    for (int s = 0; s <= g; ++s) {
      int pos = s;
      for (int k = 0; k < levels; ++k)
        if (nparts & (1 << k))
          pos = jump_[static_cast<std::size_t>(k)][static_cast<std::size_t>(pos)];
      if (pos >= s + n_) return s;
    }
    return -1;
  }
  std::vector<Arc> greedy_arcs(int start, double bound) const {
    std::vector<Arc> arcs;
    int pos = start;
    while (pos < start + n_) {
      const int e = greedy_end(pos, start + n_, bound);
      arcs.push_back({pos, e - pos});
      pos = e;
    }
    return arcs;
  }

 private:
  int n_;
  std::vector<double> p_;
  mutable std::vector<std::vector<int>> jump_;
};

// Refinement (header: Refinement): pair moves, then chain moves. Returns the number of moves.
class BoundaryRefiner {
 public:
  BoundaryRefiner(std::span<const double> w, std::vector<Arc>& arcs)
      : w_(w), arcs_(arcs), n_(static_cast<int>(w.size())), np_(static_cast<int>(arcs.size())) {
    work_.resize(arcs_.size());
    for (std::size_t k = 0; k < work_.size(); ++k) work_[k] = arc_work(w_, arcs_[k]);
  }

  int run() {
    if (np_ < 2) return 0;
    int moves = 0;
    const int max_moves = 64 * n_ + 64;  // never reached (see the header)
    for (;;) {
      moves += pair_sweeps(max_moves - moves);
      if (moves >= max_moves || !chain_move()) break;
      ++moves;
    }
    return moves;
  }

 private:
  std::size_t at(int k) const { return static_cast<std::size_t>(((k % np_) + np_) % np_); }
  double sector(int s) const { return w_[static_cast<std::size_t>(((s % n_) + n_) % n_)]; }
  double last_of(int k) const { return sector(arcs_[at(k)].first + arcs_[at(k)].count - 1); }
  double first_of(int k) const { return sector(arcs_[at(k)].first); }
  void recompute(int k) { work_[at(k)] = arc_work(w_, arcs_[at(k)]); }

  // Sweeps over the boundaries (k, k + 1): the heavier arc gives its end sector to the lighter
  // one if that strictly lowers the larger of the two works.
  int pair_sweeps(int budget) {
    int moves = 0;
    bool changed = true;
    while (changed && moves < budget) {
      changed = false;
      for (int k = 0; k < np_; ++k) {
        const std::size_t a = at(k), b = at(k + 1);
        if (work_[a] > work_[b] && arcs_[a].count >= 2) {
          const double x = last_of(k);
          if (x > 0.0 && work_[b] + x < work_[a]) {
            --arcs_[a].count;
            arcs_[b].first = (arcs_[b].first - 1 + n_) % n_;
            ++arcs_[b].count;
            recompute(k);
            recompute(k + 1);
            changed = true;
            ++moves;
          }
        } else if (work_[b] > work_[a] && arcs_[b].count >= 2) {
          const double x = first_of(k + 1);
          if (x > 0.0 && work_[a] + x < work_[b]) {
            arcs_[b].first = (arcs_[b].first + 1) % n_;
            --arcs_[b].count;
            ++arcs_[a].count;
            recompute(k);
            recompute(k + 1);
            changed = true;
            ++moves;
          }
        }
      }
    }
    return moves;
  }

  // The heaviest arc m (lowest index among equals) gives one end sector to its neighbour, which
  // passes one sector on, ..., to the arc L steps away: the L boundaries between them each move
  // by one sector. Tried for L = 1 .. np - 1, towards m + 1 then towards m - 1; the first chain
  // leaving every changed arc strictly lighter than W_max is applied.
  bool chain_move() {
    int m = 0;
    for (int k = 1; k < np_; ++k)
      if (work_[at(k)] > work_[at(m)]) m = k;
    const double wmax = work_[at(m)];
    if (arcs_[at(m)].count < 2) return false;
    for (int len = 1; len < np_; ++len) {
      for (const int dir : {+1, -1}) {
        double carried = dir > 0 ? last_of(m) : first_of(m);
        if (!(carried > 0.0)) continue;
        bool ok = true;
        for (int j = 1; j <= len && ok; ++j) {
          const int a = m + dir * j;
          double next = work_[at(a)] + carried;
          if (j < len) {
            carried = dir > 0 ? last_of(a) : first_of(a);
            next -= carried;
          }
          ok = next < wmax;
        }
        if (!ok) continue;
        for (int j = 0; j <= len; ++j) {
          Arc& arc = arcs_[at(m + dir * j)];
          if (dir > 0) {
            if (j > 0) arc.first = (arc.first - 1 + n_) % n_;
            if (j == 0) --arc.count;
            if (j == len) ++arc.count;
          } else {
            if (j < len) arc.first = (arc.first + 1) % n_;
            if (j == 0) --arc.count;
            if (j == len) ++arc.count;
          }
        }
        for (int j = 0; j <= len; ++j) recompute(m + dir * j);
        return true;
      }
    }
    return false;
  }

  std::span<const double> w_;
  std::vector<Arc>& arcs_;
  std::vector<double> work_;
  int n_, np_;
};

int refine_boundaries(std::span<const double> w, SectorPartition& part) {
  const int moves = BoundaryRefiner(w, part.arcs).run();
  if (moves > 0) part = from_arcs(part.n_sectors, std::move(part.arcs), std::move(part.method));
  return moves;
}

// METIS's part vector as arcs (false, with the reason, unless every part is one non-empty arc).
bool arcs_from_parts(const std::vector<idx_t>& part, int nparts, std::vector<Arc>& arcs,
                     std::string& reason) {
  const int n = static_cast<int>(part.size());
  std::vector<int> starts(static_cast<std::size_t>(nparts), 0);
  std::vector<int> first(static_cast<std::size_t>(nparts), -1);
  std::vector<int> size(static_cast<std::size_t>(nparts), 0);
  for (int s = 0; s < n; ++s) {
    const idx_t q = part[static_cast<std::size_t>(s)];
    if (q < 0 || q >= nparts) {
      reason = "METIS returned part " + std::to_string(q);
      return false;
    }
    ++size[static_cast<std::size_t>(q)];
    if (q != part[static_cast<std::size_t>((s - 1 + n) % n)]) {
      ++starts[static_cast<std::size_t>(q)];
      first[static_cast<std::size_t>(q)] = s;
    }
  }
  arcs.clear();
  for (int q = 0; q < nparts; ++q) {
    const auto k = static_cast<std::size_t>(q);
    if (size[k] == 0) {
      reason = "METIS left part " + std::to_string(q) + " empty";
      return false;
    }
    if (starts[k] != 1) {
      reason = "METIS part " + std::to_string(q) + " is " + std::to_string(starts[k]) + " arcs";
      return false;
    }
    arcs.push_back({first[k], size[k]});
  }
  return true;
}

std::string format_ratio(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4f", v);
  return buf;
}

}  // namespace

int sector_of(Vec2 x, Vec2 center, int n_sectors) {
  double angle = std::atan2(x.y - center.y, x.x - center.x);
  if (angle < 0.0) angle += kTwoPi;
  const double s = std::floor(angle / (kTwoPi / n_sectors));
  if (!(s > 0.0)) return 0;  // also NaN
  if (s >= n_sectors - 1) return n_sectors - 1;
  return static_cast<int>(s);
}

std::vector<double> part_work(std::span<const double> sector_work, const SectorPartition& p) {
  std::vector<double> out;
  out.reserve(p.arcs.size());
  for (Arc a : p.arcs) out.push_back(arc_work(sector_work, a));
  return out;
}

double imbalance(std::span<const double> sector_work, const SectorPartition& p) {
  const std::vector<double> w = part_work(sector_work, p);
  if (w.empty()) return 1.0;
  double total = 0.0, max = 0.0;
  for (double v : w) {
    total += v;
    max = std::max(max, v);
  }
  if (total <= 0.0) return 1.0;
  return max / (total / static_cast<double>(w.size()));
}

bool is_valid(const SectorPartition& p) {
  const int n = p.n_sectors, np = p.parts();
  if (n < 1 || np < 1 || np > n || p.owner.size() != static_cast<std::size_t>(n)) return false;
  int covered = 0;
  for (int k = 0; k < np; ++k) {
    const Arc a = p.arcs[static_cast<std::size_t>(k)];
    if (a.count < 1 || a.first < 0 || a.first >= n) return false;
    if (k > 0 && a.first <= p.arcs[static_cast<std::size_t>(k - 1)].first) return false;
    const int next =
        (k + 1 < np) ? p.arcs[static_cast<std::size_t>(k + 1)].first : p.arcs[0].first + n;
    if (a.first + a.count != next) return false;
    for (int j = 0; j < a.count; ++j)
      if (p.owner[static_cast<std::size_t>((a.first + j) % n)] != k) return false;
    covered += a.count;
  }
  return covered == n;
}

SectorPartition partition_equal_angle(int n_sectors, int nparts) {
  check_parts(n_sectors, nparts);
  std::vector<Arc> arcs;
  for (std::int64_t k = 0; k < nparts; ++k) {
    const auto b = static_cast<int>(k * n_sectors / nparts);
    const auto e = static_cast<int>((k + 1) * n_sectors / nparts);
    arcs.push_back({b, e - b});
  }
  return from_arcs(n_sectors, std::move(arcs), "equal-angle");
}

SectorPartition partition_ring_exact(std::span<const double> sector_work, int nparts) {
  const int n = static_cast<int>(sector_work.size());
  check_parts(n, nparts);
  check_weights(sector_work, sector_work.size(), "sector_work");
  double total = 0.0, wmax = 0.0;
  for (double v : sector_work) {
    total += v;
    wmax = std::max(wmax, v);
  }
  const RingPrefix prefix(sector_work);
  double hi = std::max(wmax, total / nparts);  // the lower bound L
  int start = prefix.feasible_start(hi, nparts);
  if (start < 0) {
    double lo = hi;  // infeasible
    hi = total;      // feasible: one arc from sector 0 weighs P[n] - P[0] = total exactly
    start = 0;
    for (;;) {
      const double mid = lo + 0.5 * (hi - lo);
      if (!(mid > lo && mid < hi)) break;
      const int s = prefix.feasible_start(mid, nparts);
      if (s >= 0) {
        hi = mid;
        start = s;
      } else {
        lo = mid;
      }
    }
  }
  std::vector<Arc> arcs = prefix.greedy_arcs(start, hi);
  // Split until there are nparts arcs: the heaviest arc with >= 2 sectors, at its most even cut.
  while (static_cast<int>(arcs.size()) < nparts) {
    std::size_t best = arcs.size();
    double best_work = -1.0;
    for (std::size_t k = 0; k < arcs.size(); ++k) {
      if (arcs[k].count < 2) continue;
      const double wk = arc_work(sector_work, arcs[k]);
      if (wk > best_work) {
        best_work = wk;
        best = k;
      }
    }
    const Arc a = arcs[best];
    int best_cut = 1;
    double best_max = -1.0, left = 0.0;
    for (int c = 1; c < a.count; ++c) {
      left += sector_work[static_cast<std::size_t>((a.first + c - 1) % n)];
      const double m = std::max(left, arc_work(sector_work, {a.first + c, a.count - c}));
      if (best_max < 0.0 || m < best_max) {
        best_max = m;
        best_cut = c;
      }
    }
    arcs[best] = {a.first, best_cut};
    arcs.insert(arcs.begin() + static_cast<std::ptrdiff_t>(best) + 1,
                Arc{a.first + best_cut, a.count - best_cut});
  }
  return from_arcs(n, std::move(arcs), "ring-exact");
}

SectorPartition partition_metis(std::span<const double> sector_work,
                                std::span<const double> boundary_weight, int nparts) {
  const int n = static_cast<int>(sector_work.size());
  check_parts(n, nparts);
  check_weights(sector_work, sector_work.size(), "sector_work");
  check_weights(boundary_weight, sector_work.size(), "boundary_weight");
  SectorPartition exact = partition_ring_exact(sector_work, nparts);
  auto fallback = [&](const std::string& reason) {
    exact.method = "ring-exact (fallback: " + reason + ")";
    return exact;
  };
  if (nparts == 1) return fallback("one part");
  if (n < kMetisMinSectorsPerPart * nparts)
    return fallback("fewer than " + std::to_string(kMetisMinSectorsPerPart) + " sectors per part");

  double total = 0.0, bmax = 0.0, wmax = 0.0;
  for (double v : sector_work) {
    total += v;
    wmax = std::max(wmax, v);
  }
  if (wmax > kMetisMaxSectorShare * total / nparts)
    return fallback("a sector weighs " + format_ratio(wmax * nparts / total) + " parts");
  for (double v : boundary_weight) bmax = std::max(bmax, v);
  const auto un = static_cast<std::size_t>(n);
  std::vector<idx_t> xadj(un + 1), adjncy(2 * un), vwgt(un), adjwgt(2 * un), part(un, 0);
  std::vector<idx_t> edge(un);
  for (std::size_t s = 0; s < un; ++s) {
    vwgt[s] = total > 0.0
                  ? std::max<idx_t>(
                        1, static_cast<idx_t>(std::llround(sector_work[s] * kVertexScale / total)))
                  : 1;
    edge[s] = bmax > 0.0
                  ? std::max<idx_t>(
                        1, static_cast<idx_t>(std::llround(boundary_weight[s] * kEdgeScale / bmax)))
                  : 1;
  }
  for (std::size_t s = 0; s < un; ++s) {
    const std::size_t prev = (s + un - 1) % un, next = (s + 1) % un;
    xadj[s] = static_cast<idx_t>(2 * s);
    adjncy[2 * s] = static_cast<idx_t>(prev);
    adjwgt[2 * s] = edge[prev];
    adjncy[2 * s + 1] = static_cast<idx_t>(next);
    adjwgt[2 * s + 1] = edge[s];
  }
  xadj[un] = static_cast<idx_t>(2 * un);
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_CONTIG] = 1;
  options[METIS_OPTION_SEED] = kMetisSeed;
  options[METIS_OPTION_UFACTOR] = kMetisUfactor;
  options[METIS_OPTION_NCUTS] = kMetisNcuts;
  options[METIS_OPTION_NUMBERING] = 0;
  idx_t nvtxs = n, ncon = 1, np = nparts, edgecut = 0;
  const int status =
      METIS_PartGraphKway(&nvtxs, &ncon, xadj.data(), adjncy.data(), vwgt.data(), nullptr,
                          adjwgt.data(), &np, nullptr, nullptr, options, &edgecut, part.data());
  if (status != METIS_OK) return fallback("METIS_PartGraphKway returned " + std::to_string(status));
  std::vector<Arc> arcs;
  std::string reason;
  if (!arcs_from_parts(part, nparts, arcs, reason)) return fallback(reason);

  SectorPartition result = from_arcs(n, std::move(arcs), "metis");
  if (refine_boundaries(sector_work, result) > 0) result.method = "metis+refine";
  const std::vector<double> wm = part_work(sector_work, result);
  const std::vector<double> we = part_work(sector_work, exact);
  const double max_metis = *std::max_element(wm.begin(), wm.end());
  const double max_exact = *std::max_element(we.begin(), we.end());
  const double mean = total / nparts;
  if (max_metis <= std::max(kMetisAccept * mean, max_exact) * (1.0 + kRelativeSlack)) return result;
  return fallback(result.method + " max/mean " + format_ratio(max_metis / mean) + " > " +
                  format_ratio(std::max(kMetisAccept, max_exact / mean)));
}

double arc_begin_angle(const SectorPartition& p, int part) {
  return p.arcs[static_cast<std::size_t>(part)].first * (kTwoPi / p.n_sectors);
}

double arc_end_angle(const SectorPartition& p, int part) {
  const Arc a = p.arcs[static_cast<std::size_t>(part)];
  return (a.first + a.count) * (kTwoPi / p.n_sectors);
}

double distance_to_ray(Vec2 x, Vec2 center, Vec2 u) {
  const Vec2 p = x - center;
  return dot(u, p) > 0.0 ? std::abs(cross(u, p)) : norm(p);
}

double distance_to_wedge(Vec2 x, Vec2 center, double angle_begin, double angle_end) {
  double span = angle_end - angle_begin;
  if (span >= kTwoPi) return 0.0;
  span -= kTwoPi * std::floor(span / kTwoPi);
  if (span <= 0.0) return 0.0;  // end = begin mod 2 pi: the full plane
  const Vec2 p = x - center;
  if (p.x == 0.0 && p.y == 0.0) return 0.0;
  double rel = std::atan2(p.y, p.x) - angle_begin;
  rel -= kTwoPi * std::floor(rel / kTwoPi);
  if (rel <= span) return 0.0;
  const Vec2 ub{std::cos(angle_begin), std::sin(angle_begin)};
  const Vec2 ue{std::cos(angle_end), std::sin(angle_end)};
  return std::min(distance_to_ray(x, center, ub), distance_to_ray(x, center, ue));
}

double distance_to_part(Vec2 x, Vec2 center, const SectorPartition& p, int part) {
  if (p.arcs[static_cast<std::size_t>(part)].count >= p.n_sectors) return 0.0;
  return distance_to_wedge(x, center, arc_begin_angle(p, part), arc_end_angle(p, part));
}

}  // namespace dem2d
