// MpiDomain: the Domain verbs over MPI with the angular-sector decomposition
// (docs/architecture.md, "Angular-sector domain decomposition").
//
// Regions. The plane is cut into n thin angular sectors about the drum centre (the scene
// centre without a drum), sector_of() in parallel/sector_partition.hpp. METIS groups them into
// one contiguous arc per rank, weighted by the particles in each sector (edges: particles near
// the common boundary). A rank's region is the wedge of its arc.
//
// Ownership and ghosts. A particle belongs to the rank whose wedge holds its centre, decided
// at neighbour rebuilds only (between rebuilds a particle may drift a little past its wedge:
// the Verlet skin covers that). It is a ghost on every other rank whose wedge lies within the
// halo width (2 r_max + skin) of it as a true distance (distance_to_wedge), which stays right
// at the drum centre, where all wedges meet, and for wedges wider than pi.
//
// Plans and transport. A plan lists, per peer rank, the local indices of the particles to
// send and the number to receive (and, for a migration, the contact-history records that go
// with them and the number of records to receive); the transport moves one message per peer
// for a plan, point to point: the bytes of any set of registered fields (FieldBase::pack_items /
// unpack_items, field by field), after an optional header, followed by the records. One plan
// serves every field. Every plan is made the same way (make_plan: one all-to-all of the counts
// tells each rank what it receives), and every byte between ranks goes through the one
// transport: the halo plan is built at each rebuild and reused by refresh_ghosts and the
// end-of-step round; a migration builds its own plan (the particles that left, with every
// registered field and the contact histories that involve them) and sends it the same way.
//
// Checks. A particle that left its region by more than the halo width since the last
// rebuild (it jumped past the ghosts of its new owner) is a hard error naming it; the global
// particle count is compared before and after every migration. Errors are agreed on: every
// rank throws the same message.
//
// Load balance. After each rebuild the core reports the work of each owned particle (1 + its
// share of the listed pairs); the sector weights are these summed by sector, so a dense pile
// weighs more than the same number of balls in flight;
// when max/mean over ranks exceeds `repartition_threshold` and at least `repartition_gap`
// rebuilds passed since the last partition (hysteresis), the next migrate() repartitions.
//
// One round per step. With few ranks (at most kAllPeersRanks) every rank is a halo peer of
// every other, even with no ghosts to send, so that exchange_step() can carry the step's
// reduction (a handful of doubles) in the same messages as the ghosts' next state: one
// synchronisation per velocity-Verlet step. With more ranks the peers are the neighbours only
// and exchange_step() is the ghost refresh plus an MPI_Allreduce.
//
// Reductions are exact (max, logical or, integer sums) or order-fixed (double sums gathered and
// added in rank order), so they give the same bits on every rank. Every MPI call goes through
// parallel/comm.hpp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/base/scene.hpp"
#include "core/base/vec2.hpp"
#include "core/step/domain.hpp"
#include "parallel/comm.hpp"
#include "parallel/sector_partition.hpp"

namespace dem2d {

struct DecompositionOptions {
  Vec2 center{};            // sectors are cut about this point (the drum centre)
  bool has_center = false;  // false: the centre of the particles' bounding box
  // 32: bench/partition finds that contiguous arcs of 16 sectors per rank cannot balance a
  // settled charge within 5 % from 4 ranks up (granularity), 24 can, and from 32 METIS's
  // own grouping is mostly kept.
  int sectors_per_rank = 32;
  double repartition_threshold = 1.05;  // max/mean work that triggers a repartition
  int repartition_gap = 10;             // rebuilds between two partitions at least
};

// The decomposition a scene asks for: sectors about the drum centre (the particles' centre
// without a drum), with the deck's sectors per rank and repartition threshold.
DecompositionOptions decomposition_of(const Scene& scene);

// What the decomposition did, for run.json and bench/strong_scaling.
struct DecompositionStats {
  int partitions = 0;           // METIS partitions computed (1 = the initial one)
  std::string method;           // how the last partition was found
  double imbalance_work = 1.0;  // max/mean of the last reported work
  double imbalance_sum = 0.0;   // sum of imbalance_work over the rebuilds so far
  std::int64_t reports = 0;     // rebuilds reported
  double imbalance_mean() const {
    return reports ? imbalance_sum / static_cast<double>(reports) : 1.0;
  }
  double imbalance_equal_angle = 1.0;  // the same for equal-angle arcs at the last partition
  double imbalance_partition = 1.0;    // predicted (sector weights) at the last partition
  std::int64_t migrated = 0;           // particles sent by this rank, all rebuilds
  std::int64_t ghosts = 0;             // ghosts on this rank after the last halo exchange
  double comm_seconds = 0.0;           // wall time in migrate / exchange_halo / refresh_ghosts
  double work = 0.0;                   // this rank's last reported work
};

// Per-rank figures of the decomposition, in rank order (run.json).
struct RankStats {
  std::vector<double> work;          // DecompositionStats::work of each rank
  std::vector<double> ghosts;        // DecompositionStats::ghosts
  std::vector<double> comm_seconds;  // DecompositionStats::comm_seconds
};

class MpiDomain final : public Domain {
 public:
  MpiDomain(MPI_Comm comm, const DecompositionOptions& options = {});
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  double sum(double x) const override;
  double max(double x) const override;
  std::int64_t sum(std::int64_t x) const override;
  bool any(bool x) const override;
  void max(std::span<double> values) const override;
  void sum(std::span<std::int64_t> values) const override;
  void sum(std::span<double> values) const override;
  std::vector<std::int64_t> allgather(std::span<const std::int64_t> mine) const override;
  bool owns(Vec2 x) const override { return owner_of(x) == rank_; }
  void population_changed(std::int64_t total) override { total_particles_ = total; }

  void adopt(ParticleStore& p, double halo_width) override;
  void migrate(ParticleStore& p, HistoryRecords& histories) override;
  void exchange_halo(ParticleStore& p) override;
  void refresh_ghosts(ParticleStore& p, std::span<FieldBase* const> fields) override;
  void report_work(std::span<const double> particle_work) override;
  std::span<const std::int32_t> halo_sources() const override { return halo_sources_; }
  void exchange_step(ParticleStore& p, std::span<FieldBase* const> send_fields,
                     std::span<FieldBase* const> recv_fields, std::span<double> values) override;

  // Up to this many ranks, the halo plan lists every other rank as a peer (see above).
  static constexpr int kAllPeersRanks = 4;

  const SectorPartition& partition() const { return partition_; }
  // The rank owning a point (its sector's part).
  int owner_of(Vec2 x) const;
  double halo_width() const { return halo_width_; }
  const DecompositionStats& stats() const { return stats_; }
  // The rank each ghost slot came from (ghost g is store index n_owned() + g).
  std::vector<int> ghost_origin() const;
  // Every rank's work, ghosts and communication time, gathered (collective).
  RankStats gather_rank_stats() const;

 private:
  // Who sends what to whom: per peer rank, local indices to send and the count to receive;
  // for a migration also the history records (indices into the HistoryRecords) that travel
  // with the particles and the count of records to receive (both empty for the halo).
  struct Plan {
    std::vector<int> peers;                              // ranks exchanged with, ascending
    std::vector<std::vector<std::int32_t>> send;         // per peer: local particle indices
    std::vector<std::size_t> recv_count;                 // per peer: particles
    std::vector<std::vector<std::size_t>> send_records;  // per peer: history records
    std::vector<std::size_t> recv_records;               // per peer: history records
  };
  // The bytes of one message: `header`, then `per_particle` for each particle, then
  // `per_record` for each history record.
  struct MessageLayout {
    std::size_t header = 0;
    std::size_t per_particle = 0;
    std::size_t per_record = 0;
  };
  void repartition(const ParticleStore& p);
  void rebuild_wedges();
  // The plan that sends to[q] (local indices) and records_to[q] (history records; an empty
  // `records_to`: none) to each rank q. One all-to-all of the counts tells each rank what it
  // receives. Peers: every other rank when `all_peers`, else the ranks with traffic either way.
  Plan make_plan(std::vector<std::vector<std::int32_t>> to,
                 std::vector<std::vector<std::size_t>> records_to, bool all_peers) const;
  // Ghosts' `recv_fields` from their owners' `send_fields`; `values`, when not empty, travel
  // ahead of the ghosts in every message and are maximised (all ranks must be peers).
  void fill_ghosts(ParticleStore& p, std::span<FieldBase* const> send_fields,
                   std::span<FieldBase* const> recv_fields, std::span<double> values = {});
  // Migration, in order: the new owner of each owned particle (a jump past the halo is an
  // error agreed on by every rank), the plan, its messages, and the arrivals appended.
  std::vector<int> new_owners(const ParticleStore& p, bool repartitioned) const;
  Plan migration_plan(const ParticleStore& p, const HistoryRecords& histories,
                      const std::vector<int>& owner) const;
  void pack_migration(const ParticleStore& p, const HistoryRecords& histories, const Plan& plan);
  void unpack_migration(ParticleStore& p, HistoryRecords& histories, const Plan& plan) const;
  // The one point-to-point exchange of a plan's messages: send[u] to plan.peers[u], recv[u]
  // (sized here from the plan and `layout`) from it. Used by the halo, the end-of-step round
  // and migration alike.
  void transport(const Plan& plan, const MessageLayout& layout,
                 const std::vector<std::vector<std::byte>>& send,
                 std::vector<std::vector<std::byte>>& recv);

  MPI_Comm comm_;
  int rank_ = 0;
  int size_ = 1;
  DecompositionOptions options_;
  SectorPartition partition_;
  std::vector<double> wedge_begin_, wedge_end_;  // per rank, radians
  double halo_width_ = 0.0;
  std::int64_t total_particles_ = 0;
  Plan halo_;
  std::vector<std::int32_t> halo_sources_;  // union of halo_.send, ascending
  bool all_peers_ = false;                  // every other rank is in halo_.peers
  // Message buffers, kept between calls: the halo refresh runs every step.
  std::vector<std::vector<std::byte>> send_buffers_, recv_buffers_;
  std::vector<MPI_Request> requests_;
  std::vector<double> reduce_buffer_;  // exchange_step without all peers: values and NaN flags
  std::vector<double> particle_work_;  // last reported, per owned particle, until the next migrate
  bool repartition_due_ = false;
  int rebuilds_since_partition_ = 0;
  DecompositionStats stats_;
};

}  // namespace dem2d
