// Storage order of the particles: along a Hilbert curve through a grid of cells, so that
// particles close in space are close in memory and a sweep over the contacts walks memory in
// order (docs/performance.md, "Storage order").
//
// The physics does not see the storage order: the neighbour lists are built in canonical order
// (core/contact/neighbors.hpp: pairs by (id_i, id_j), partners in id order), so a particle's forces
// are summed in the order of its partners' ids whatever the storage order, and sorting changes no
// bit of any particle's state. Sums over particles for diagnostics (energies in series.csv)
// follow the storage order and may differ in the last bits, as they do between rank counts.
//
// When to sort (SpatialSort::kAuto): at a rebuild, when this rank owns at least kMinParticles
// particles and more than kFarFraction of the pairs of the last lists join particles more than
// NeighborSearch::kNear apart in storage (their ids are spatially random: a mixed charge, or
// fragments that took new ids). Below that the particle data sit in the caches, or the order is
// already local (a fill's row-by-row ids), and the canonical scatter is cheaper than the sorted
// store's force records (docs/performance.md, "Storage order": at 1e5 particles sorting did not
// pay even with random ids; at 1e6 with random ids it is 1.4 times faster). Once sorted, the
// store is sorted again when mixing has made the pairs far again.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/base/scene.hpp"
#include "core/shape/particles.hpp"

namespace dem2d {

// The permutation (new[k] = old[order[k]]) that puts the owned particles in Hilbert order of
// their cells (side `cell`), ties broken by id. Ghosts are not looked at.
std::vector<std::size_t> hilbert_order(const ParticleStore& p, double cell);

// Index along the Hilbert curve of order `bits` (a 2^bits x 2^bits grid) of cell (x, y).
std::uint64_t hilbert_index(std::uint32_t x, std::uint32_t y, int bits);

class SortPolicy {
 public:
  static constexpr std::size_t kMinParticles = 250000;
  static constexpr double kFarFraction = 0.3;

  explicit SortPolicy(SpatialSort mode = SpatialSort::kAuto) : mode_(mode) {}
  // Whether to sort the store at this rebuild (before its lists are built).
  bool due(std::size_t n_owned) const;
  // The lists were built: their far fraction, and whether the store was just sorted.
  void built(double far_fraction, bool sorted_now);
  std::int64_t sorts() const { return sorts_; }

 private:
  SpatialSort mode_;
  double far_ = 0.0;  // of the last lists
  std::int64_t sorts_ = 0;
};

}  // namespace dem2d
