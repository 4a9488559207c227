// Angular-sector partition of the drum cross-section (the MPI decomposition).
//
// Sectors. The plane is cut into n thin angular sectors about the drum centre c. A point x has
// the angle theta = atan2(x_y - c_y, x_x - c_x), mapped to [0, 2 pi) by adding 2 pi to negative
// values, and lies in sector s = floor(theta / (2 pi / n)), clamped to [0, n - 1] (the clamp
// catches theta + 2 pi rounding up to exactly 2 pi for points just below the +x axis; the centre
// itself, atan2(0, 0) = 0, is in sector 0). sector_of is THE ownership rule: every caller that
// decides which rank owns a particle (migration, the halo, the benches) calls it, so that two
// ranks never disagree about a particle sitting on a sector edge. Sector s covers the angles
// [s 2 pi / n, (s + 1) 2 pi / n); the ray at angle s 2 pi / n is "boundary s", between sectors
// s - 1 and s (mod n).
//
// Parts. The sectors form a ring graph (s adjacent to s - 1 and s + 1 mod n). A partition gives
// each of nparts parts (ranks) one contiguous arc of sectors, Arc{first, count}: the sectors
// first, first + 1, ..., first + count - 1 (mod n), count >= 1, so that a rank's region is one
// wedge. Canonical numbering (every method): part k is the arc with the k-th smallest first
// sector; the last part may wrap through sector 0. owner[s] is the part of sector s.
// All functions here are pure and deterministic (no MPI, no clocks, no global random state):
// every rank computing a partition from the same inputs gets the same bits.
//
// Methods.
//  - partition_equal_angle: arc k = sectors [floor(k n / p), floor((k + 1) n / p)) (baseline).
//  - partition_ring_exact: contiguous arcs minimising the largest arc work W_max (the
//    bottleneck). feasible(B): some start offset from which a greedy walk (each arc takes
//    sectors while its work, a difference of prefix sums over the doubled ring, stays <= B)
//    closes the ring in <= p arcs. Only starts 0 .. g need trying, where the greedy arc from
//    sector 0 is sectors 0 .. g - 1: in any feasible partition the arc holding sector 0 ends at
//    or before sector g - 1 (its part from sector 0 on weighs <= B), so the next arc starts in
//    1 .. g (or one arc is the whole ring: start 0). The greedy arc end from every position is
//    found by two pointers, and p arcs from one start by binary lifting (jump tables of
//    2^k arcs): O(n log p) per test. The optimum lies in [L, total], L = max(max sector work,
//    total / p); bisection on B (about 60 halvings, until the bounds are adjacent doubles)
//    finds the smallest feasible B; the greedy partition at that B has W_max = the optimum (it
//    is an arc sum, feasible, and no arc sum lies strictly between the bounds). Fewer than p
//    greedy arcs are then split (the heaviest arc with >= 2 sectors, at its most even cut)
//    until there are p; splitting never raises W_max. Ties: the smallest feasible start.
//    n = 4096, p = 64: a few ms.
//  - partition_metis: METIS_PartGraphKway on the ring. Vertex weights
//    vwgt_s = max(1, round(w_s kVertexScale / total)) (total = sum of w; all ones if total = 0),
//    edge weights adjwgt(s, s + 1) = max(1, round(b_s kEdgeScale / max b)) (all ones if
//    max b = 0), options: METIS_OPTION_CONTIG = 1, METIS_OPTION_SEED = kMetisSeed,
//    METIS_OPTION_UFACTOR = kMetisUfactor (max part weight <= 1.02 x mean), NCUTS = 4.
//    The result is then VERIFIED: every part non-empty and one contiguous arc (a connected part
//    of a ring is an arc, but METIS may return empty or disconnected parts); otherwise, and
//    when METIS fails, the exact ring partition is used instead. METIS is not called at all
//    (exact ring partition) for p = 1, for fewer than kMetisMinSectorsPerPart = 4 sectors per
//    part, or when one sector weighs more than half a mean part: on such graphs METIS cannot
//    balance contiguous parts, returns empty parts and prints errors on stderr.
//    Refinement: deterministic local moves, each shifting arc boundaries by one sector:
//     (a) pair sweeps: over the boundaries between consecutive arcs (k, k + 1), k = 0 .. p - 1,
//         where the heavier arc gives its end sector to the lighter one and this strictly
//         lowers the larger of the two works (and keeps the giver non-empty), do it; repeat
//         sweeps until one changes nothing. Each move lowers sum W_k^2 strictly (moving weight
//         x from a to b with b + x < a changes it by 2x(b + x - a) < 0), so they end;
//     (b) one chain move: the heaviest arc m (lowest index among equals) gives an end sector
//         to its neighbour, which passes its far end sector on, ..., to the arc L steps away
//         (the L boundaries in between each move by one sector; L = 1 .. p - 1, towards m + 1
//         first, then m - 1); the first chain that leaves every changed arc strictly lighter
//         than W_max is applied, then back to (a). Stops when no chain lowers the heaviest arc.
//    No move raises W_max, and (W_max, number of arcs at W_max) falls at every chain move.
//    Acceptance: the refined METIS partition is kept if its W_max <= max(kMetisAccept x mean,
//    optimum W_max) (relative slack 1e-12); otherwise the exact ring partition is returned.
//    METIS (with the edge weights) chooses where the cuts go when balance allows a choice: cuts
//    across lightly populated boundary rays, i.e. a smaller halo; the exact ring partition
//    ignores the edge weights.
//    SectorPartition::method says what was returned: "metis", "metis+refine" (refinement moved
//    at least one boundary), or "ring-exact (fallback: REASON)".
//  Every method throws std::invalid_argument for p < 1, p > n, a work or boundary span of the
//  wrong size, or a negative or non-finite weight: a part can never be empty.
//
// Wedges. Part k's wedge is the closed set of points whose angle lies counter-clockwise from
// arc_begin_angle = first 2 pi / n to arc_end_angle = (first + count) 2 pi / n (not reduced
// mod 2 pi: end - begin = count 2 pi / n, in (0, 2 pi]). distance_to_wedge(x, c, a, b) is the
// Euclidean distance from x to that set: span = b - a reduced to (0, 2 pi] (span >= 2 pi, or
// b = a mod 2 pi, is the full plane: 0). Inside (x = c, or the angle of x - c measured from a,
// reduced to [0, 2 pi), is <= span): 0. Outside: the nearest point of the wedge is on one of
// its two bounding rays {c + t u, t >= 0}, u = (cos a, sin a) or (cos b, sin b); the distance
// to a ray is |cross(u, x - c)| if dot(u, x - c) > 0, else |x - c|; the result is the smaller
// of the two. This holds for spans above pi (the outside is then a convex wedge) and near or
// behind the centre. A particle is a ghost of rank k if another rank owns it and its distance
// to rank k's wedge is below the halo width.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "core/base/vec2.hpp"

namespace dem2d {

inline constexpr double kTwoPi = 6.283185307179586476925286766559;

// Sector of point x about centre (see above): the one ownership rule.
int sector_of(Vec2 x, Vec2 center, int n_sectors);

// Sectors first, first + 1, ..., first + count - 1 (mod n).
struct Arc {
  int first = 0;
  int count = 0;
};

struct SectorPartition {
  int n_sectors = 0;
  std::vector<int> owner;  // per sector: its part
  std::vector<Arc> arcs;   // per part, canonical order (first ascending)
  std::string method;      // how it was made (see above)
  int parts() const { return static_cast<int>(arcs.size()); }
};

// METIS_PartGraphKway (contiguous, seeded) + verification + one-sector boundary refinement;
// falls back to partition_ring_exact (see method). boundary_weight[s] weighs the edge between
// sectors s and s + 1 (mod n), i.e. boundary ray s + 1.
SectorPartition partition_metis(std::span<const double> sector_work,
                                std::span<const double> boundary_weight, int nparts);

// Contiguous arcs minimising the largest arc work (exact).
SectorPartition partition_ring_exact(std::span<const double> sector_work, int nparts);

// Equal arcs: part k = sectors [floor(k n / p), floor((k + 1) n / p)).
SectorPartition partition_equal_angle(int n_sectors, int nparts);

// Per-part work (sum of its sectors' work, summed in sector order along the arc).
std::vector<double> part_work(std::span<const double> sector_work, const SectorPartition& p);

// max part work / mean part work (1 when the total work is 0).
double imbalance(std::span<const double> sector_work, const SectorPartition& p);

// True if every part is one non-empty contiguous arc, the arcs cover every sector once, owner
// agrees with arcs and the arcs are in canonical order.
bool is_valid(const SectorPartition& p);

// The wedge of a part: angles from begin counter-clockwise to end (end - begin in (0, 2 pi]).
double arc_begin_angle(const SectorPartition& p, int part);
double arc_end_angle(const SectorPartition& p, int part);

// Distance from x to the ray {center + t u, t >= 0} (u a unit vector).
double distance_to_ray(Vec2 x, Vec2 center, Vec2 u);

// Euclidean distance from x to the closed wedge {angle from angle_begin ccw to angle_end}.
double distance_to_wedge(Vec2 x, Vec2 center, double angle_begin, double angle_end);

// distance_to_wedge for a part's wedge; exactly 0 for a part holding all the sectors.
double distance_to_part(Vec2 x, Vec2 center, const SectorPartition& p, int part);

}  // namespace dem2d
