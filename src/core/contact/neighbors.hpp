// Neighbour search: a cell grid (cell side >= the largest contact reach) builds a Verlet list of
// candidate pairs within r_i + r_j + skin, and a list of candidate (particle, wall element)
// contacts within r + skin of the element.
//
// Canonical order (docs/architecture.md, "Reproducibility"): every pair is stored lower id first
// and the list is sorted by (id_i, id_j). Scattering pair forces in that order adds the forces on
// each particle in the order of its partners' ids, whatever the storage order or rank count.
// When the particles are stored in spatial order the list is kept in storage order instead, and
// the kernel sums each particle's forces through its records in the same canonical order
// (PairList::records): the same bits.
// Contact history lives beside the list, `width` values per listed contact (the slots the
// contact model declares, core/contact/contact_history.hpp), and is carried to the new list at each
// rebuild by matching (id_i, id_j) keys (both lists are sorted, so this is one merge).
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "core/geometry/walls.hpp"
#include "core/shape/particles.hpp"

namespace dem2d {

struct PairList {
  Array<std::int32_t> i, j;        // local indices
  Array<std::int64_t> id_i, id_j;  // keys, id_i < id_j
  std::size_t width = 0;           // history values per contact
  Array<double> history;  // committed at the end of each step: [k * width, (k + 1) * width)
  Array<double> trial;    // written by each force evaluation (empty when it writes in place)
  // Storage order (core/fast/spatial_order.hpp). When the owned particles are not in id order, the
  // entries are kept in the order of their lower local index, so that a sweep over the list
  // walks the particle data in memory order. key_order[t] is then the entry of the t-th key in
  // canonical order, and each owned particle q has its force records record_start[q] ..
  // record_start[q + 1] in `records` (2k: entry k acting on i, 2k + 1: on j) in the order of its
  // partners' ids, the canonical order the kernel sums them in. All three are empty when the
  // entries are in canonical order.
  Array<std::int32_t> key_order;
  Array<std::int32_t> record_start, records;
  std::size_t size() const { return i.size(); }
  bool canonical() const { return key_order.empty(); }
  // The entry of the t-th key in canonical order.
  std::size_t entry(std::size_t t) const {
    return key_order.empty() ? t : static_cast<std::size_t>(key_order[t]);
  }
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
  // Whether the pair list gets trial slots (a copy of its histories; default yes): a kernel that
  // writes the histories in place needs none (ContactKernel::histories_in_place).
  void set_pair_trials(bool on) { pair_trials_ = on; }
  // Size levels (bin_particles): as their expected work says (default), always, or never (one
  // grid sized by the largest particle). Tests and benchmarks set it; the lists are the same.
  enum class Levels { kAuto, kAlways, kNever };
  void set_levels(Levels mode) { levels_mode_ = mode; }
  int levels_used() const { return static_cast<int>(levels_.size()); }
  // The storage order's locality (core/fast/spatial_order.hpp): the fraction of the last build's
  // pairs whose particles are more than kNear apart in storage.
  static constexpr std::int32_t kNear = 8192;
  double far_fraction() const { return far_fraction_; }

 private:
  // One cell grid per size level (bin_particles).
  struct Level {
    double r_max = 0.0, inv_h = 0.0;
    int nx = 0, ny = 0;
    std::size_t count = 0;
    Array<std::int32_t> start, items, fill;
  };
  static constexpr int kMaxLevels = 8;  // radii within a factor 2^8 of the largest share a level
  // The levels are used when their expected work is below this share of one grid's.
  static constexpr double kLevelsGain = 0.7;

  void sort_by_id(const ParticleStore& p);
  void bin_particles(const ParticleStore& p, double skin);
  std::pair<int, int> cell(const Level& l, Vec2 x) const;
  bool levels_pay(Vec2 box, double r_max, double skin) const;
  void find_partners(const ParticleStore& p, std::int32_t i, double skin);
  void build_particle_pairs(const ParticleStore& p, double skin, PairList& out);
  void build_wall_pairs(const ParticleStore& p, const Walls& walls, double skin, WallPairList& out);

  std::vector<Level> levels_;
  Vec2 lo_{};  // the grids' common corner
  Array<std::int8_t> level_of_;
  Array<std::int32_t> cell_of_, order_, scratch_;
  Array<std::int32_t> owned_order_;  // owned indices in id order, for the store's layout_
  std::uint64_t layout_ = ~std::uint64_t{0};
  bool id_ordered_ = true;  // the owned particles are in id order
  Levels levels_mode_ = Levels::kAuto;
  bool pair_trials_ = true;
  std::int64_t builds_ = 0;
  double far_fraction_ = 0.0;
};

}  // namespace dem2d
