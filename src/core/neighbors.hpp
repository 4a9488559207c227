// Neighbour search: a cell grid (cell side >= the largest contact reach) builds a Verlet list of
// candidate pairs within r_i + r_j + skin, and a list of candidate (particle, wall element)
// contacts within r + skin of the element.
//
// Canonical order (architecture.md, Reproducibility): every pair is stored lower id first and
// the list is sorted by (id_i, id_j). Scattering pair forces in that order adds the forces on
// each particle in the order of its partners' ids, whatever the storage order or rank count.
// Contact history lives beside the list, `width` values per listed contact (the slots the
// contact model declares, core/contact_history.hpp), and is carried to the new list at each
// rebuild by matching (id_i, id_j) keys (both lists are sorted, so this is one merge).
#pragma once

#include <cstdint>
#include <vector>

#include "core/particles.hpp"
#include "core/walls.hpp"

namespace dem2d {

struct PairList {
  Array<std::int32_t> i, j;        // local indices
  Array<std::int64_t> id_i, id_j;  // keys, id_i < id_j
  std::size_t width = 0;           // history values per contact
  Array<double> history;  // committed at the end of each step: [k * width, (k + 1) * width)
  Array<double> trial;    // written by each force evaluation
  std::size_t size() const { return i.size(); }
  const double* history_of(std::size_t k) const { return history.data() + k * width; }
};

struct WallPairList {
  Array<std::int32_t> particle, element;
  Array<std::int64_t> id;  // particle id (key with element)
  std::size_t width = 0;
  Array<double> history;
  Array<double> trial;
  std::size_t size() const { return particle.size(); }
  const double* history_of(std::size_t k) const { return history.data() + k * width; }
};

class NeighborSearch {
 public:
  // Rebuild both lists for the particles' current positions and the walls' current pose;
  // contact histories of pairs still listed are kept, the others dropped.
  void build(const ParticleStore& p, const Walls& walls, double skin, PairList& pairs,
             WallPairList& wall_pairs);

  // Brute-force O(N^2) candidate pairs within r_i + r_j + cutoff_extra (tests).
  static std::vector<std::pair<std::int64_t, std::int64_t>> brute_force_pairs(
      const ParticleStore& p, double cutoff_extra);

  std::int64_t builds() const { return builds_; }

 private:
  void bin_particles(const ParticleStore& p, double skin);
  void build_particle_pairs(const ParticleStore& p, double skin, PairList& out);
  void build_wall_pairs(const ParticleStore& p, const Walls& walls, double skin, WallPairList& out);

  int nx_ = 0, ny_ = 0;  // cells along x and y at the last build
  Array<std::int32_t> cell_start_, cell_items_, cell_of_, order_, scratch_;
  std::int64_t builds_ = 0;
};

}  // namespace dem2d
