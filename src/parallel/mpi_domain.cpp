#include "parallel/mpi_domain.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace dem2d {

DecompositionOptions decomposition_of(const Scene& scene) {
  DecompositionOptions d;
  d.has_center = scene.drum.present;
  d.center = scene.drum.center;
  d.sectors_per_rank = scene.run.sectors_per_rank;
  d.repartition_threshold = scene.run.repartition_threshold;
  return d;
}

namespace {

// Wall-clock accumulator for the time spent communicating.
class CommTimer {
 public:
  explicit CommTimer(double& total) : total_(total), start_(mpi::wall_time()) {}
  ~CommTimer() { total_ += mpi::wall_time() - start_; }

 private:
  double& total_;
  double start_;
};

// Owned particles [first, n_owned) in id order.
void sort_owned_by_id(ParticleStore& p, std::size_t first = 0) {
  const std::int64_t* id = p.id.data();
  if (std::is_sorted(id + first, id + p.n_owned())) return;
  std::vector<std::size_t> order(p.n_owned());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin() + static_cast<std::ptrdiff_t>(first), order.end(),
            [&](std::size_t a, std::size_t b) { return id[a] < id[b]; });
  p.permute(order);
}

}  // namespace

MpiDomain::MpiDomain(MPI_Comm comm, const DecompositionOptions& options)
    : comm_(comm), rank_(mpi::rank(comm)), size_(mpi::size(comm)), options_(options) {
  if (options_.sectors_per_rank < 1) options_.sectors_per_rank = 1;
  partition_ = partition_equal_angle(options_.sectors_per_rank * size_, size_);
  rebuild_wedges();
}

// Sum in rank order on every rank: an MPI_Allreduce may add in any order.
double MpiDomain::sum(double x) const {
  if (size_ == 1) return x;  // one rank: no MPI call in the step loop
  double s = 0.0;
  for (const double v : mpi::all_gather(comm_, x)) s += v;
  return s;
}

double MpiDomain::max(double x) const { return size_ == 1 ? x : mpi::max(comm_, x); }

std::int64_t MpiDomain::sum(std::int64_t x) const { return size_ == 1 ? x : mpi::sum(comm_, x); }

void MpiDomain::max(std::span<double> values) const {
  if (size_ > 1) mpi::max_in_place(comm_, values);
}

void MpiDomain::sum(std::span<std::int64_t> values) const {
  if (size_ > 1) mpi::sum_in_place(comm_, values);
}

void MpiDomain::sum(std::span<double> values) const {
  if (size_ > 1) mpi::sum_in_place(comm_, values);
}

std::vector<std::int64_t> MpiDomain::allgather(std::span<const std::int64_t> mine) const {
  if (size_ == 1) return {mine.begin(), mine.end()};
  return mpi::all_gather(comm_, mine);
}

bool MpiDomain::any(bool x) const { return size_ == 1 ? x : mpi::any(comm_, x); }

int MpiDomain::owner_of(Vec2 x) const {
  return partition_
      .owner[static_cast<std::size_t>(sector_of(x, options_.center, partition_.n_sectors))];
}

void MpiDomain::rebuild_wedges() {
  wedge_begin_.resize(size_);
  wedge_end_.resize(size_);
  for (int q = 0; q < size_; ++q) {
    wedge_begin_[q] = arc_begin_angle(partition_, q);
    wedge_end_[q] = arc_end_angle(partition_, q);
  }
}

// Sector weights (the work of the owned particles in each sector, as last reported, or their
// count) and boundary weights (particles within the halo width of each boundary ray), summed
// over ranks: multiples of 1/2, so the sums are exact in any order and every rank sees the same
// numbers. Rank 0 partitions and broadcasts.
void MpiDomain::repartition(const ParticleStore& p) {
  const int n = options_.sectors_per_rank * size_;
  const double step = kTwoPi / n;
  std::vector<Vec2> ray(static_cast<std::size_t>(n) + 1);  // unit direction of boundary ray s
  for (int s = 0; s <= n; ++s)
    ray[static_cast<std::size_t>(s)] = {std::cos(s * step), std::sin(s * step)};
  std::vector<double> weights(2 * static_cast<std::size_t>(n), 0.0);  // work, then boundaries
  const bool have_work = particle_work_.size() == p.n_owned();
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    const int s = sector_of(p.pos[k], options_.center, n);
    weights[static_cast<std::size_t>(s)] += have_work ? particle_work_[k] : 1.0;
    // Boundary ray s lies between sectors s - 1 and s: edge s - 1; ray s + 1: edge s.
    if (distance_to_ray(p.pos[k], options_.center, ray[static_cast<std::size_t>(s)]) < halo_width_)
      weights[static_cast<std::size_t>(n + (s + n - 1) % n)] += 1.0;
    if (distance_to_ray(p.pos[k], options_.center, ray[static_cast<std::size_t>(s) + 1]) <
        halo_width_)
      weights[static_cast<std::size_t>(n + s)] += 1.0;
  }
  mpi::sum_in_place(comm_, weights);
  const std::span<const double> work(weights.data(), static_cast<std::size_t>(n));
  const std::span<const double> edges(weights.data() + n, static_cast<std::size_t>(n));
  std::vector<int> owner(static_cast<std::size_t>(n));
  std::string method;
  if (rank_ == 0) {
    const SectorPartition part = partition_metis(work, edges, size_);
    owner = part.owner;
    method = part.method;
  }
  mpi::broadcast(comm_, owner, 0);
  method = mpi::broadcast_string(comm_, method, 0);
  // Arcs in canonical order from the owner vector: part q starts where its predecessor differs.
  SectorPartition part;
  part.n_sectors = n;
  part.owner = owner;
  part.method = method;
  part.arcs.assign(static_cast<std::size_t>(size_), Arc{});
  for (int s = 0; s < n; ++s) {
    const int q = owner[static_cast<std::size_t>(s)];
    part.arcs[static_cast<std::size_t>(q)].count += 1;
    if (owner[static_cast<std::size_t>((s + n - 1) % n)] != q)
      part.arcs[static_cast<std::size_t>(q)].first = s;
  }
  if (!is_valid(part))
    throw std::logic_error("MpiDomain: the sector partition is not one arc per rank");
  partition_ = std::move(part);
  rebuild_wedges();
  stats_.partitions += 1;
  stats_.method = method;
  stats_.imbalance_partition = imbalance(work, partition_);
  stats_.imbalance_equal_angle = imbalance(work, partition_equal_angle(n, size_));
  repartition_due_ = false;
  rebuilds_since_partition_ = 0;
}

void MpiDomain::adopt(ParticleStore& p, double halo_width) {
  CommTimer timer(stats_.comm_seconds);
  halo_width_ = halo_width;
  p.clear_ghosts();
  total_particles_ = static_cast<std::int64_t>(p.n_owned());
  if (!options_.has_center) {
    // No drum: the centre of the particles' bounding box (every rank holds every particle).
    Vec2 lo{1e300, 1e300}, hi{-1e300, -1e300};
    for (std::size_t k = 0; k < p.n_owned(); ++k) {
      lo = {std::min(lo.x, p.pos[k].x), std::min(lo.y, p.pos[k].y)};
      hi = {std::max(hi.x, p.pos[k].x), std::max(hi.y, p.pos[k].y)};
    }
    options_.center = p.n_owned() ? 0.5 * (lo + hi) : Vec2{};
    options_.has_center = true;
  }
  // Every rank holds every particle: only rank 0 contributes to the (summed) sector weights.
  if (rank_ == 0) {
    repartition(p);
  } else {
    const ParticleStore none;
    repartition(none);
  }
  std::vector<char> drop(p.n_owned(), 0);
  for (std::size_t k = 0; k < p.n_owned(); ++k) drop[k] = owner_of(p.pos[k]) != rank_ ? 1 : 0;
  p.remove_if(drop);
  if (sum(static_cast<std::int64_t>(p.n_owned())) != total_particles_)
    throw std::logic_error("MpiDomain::adopt: particles lost or duplicated");
}

void MpiDomain::report_work(std::span<const double> particle_work) {
  particle_work_.assign(particle_work.begin(), particle_work.end());
  double work = 0.0;
  for (const double w : particle_work) work += w;
  stats_.work = work;
  const double most = mpi::max(comm_, work);
  const double total = sum(work);
  const double mean = total / size_;
  stats_.imbalance_work = mean > 0.0 ? most / mean : 1.0;
  stats_.imbalance_sum += stats_.imbalance_work;
  stats_.reports += 1;
  ++rebuilds_since_partition_;
  repartition_due_ = stats_.imbalance_work > options_.repartition_threshold &&
                     rebuilds_since_partition_ >= options_.repartition_gap;
}

std::vector<int> MpiDomain::ghost_origin() const {
  std::vector<int> out;
  for (std::size_t u = 0; u < halo_.peers.size(); ++u)
    out.insert(out.end(), halo_.recv_count[u], halo_.peers[u]);
  return out;
}

RankStats MpiDomain::gather_rank_stats() const {
  return {mpi::all_gather(comm_, stats_.work),
          mpi::all_gather(comm_, static_cast<double>(stats_.ghosts)),
          mpi::all_gather(comm_, stats_.comm_seconds)};
}

MpiDomain::Plan MpiDomain::make_plan(std::vector<std::vector<std::int32_t>> to,
                                     std::vector<std::vector<std::size_t>> records_to,
                                     bool all_peers) const {
  const bool with_records = !records_to.empty();
  const std::size_t ranks = static_cast<std::size_t>(size_);
  std::vector<std::int64_t> send_n(2 * ranks, 0);  // per rank: particles, records
  for (std::size_t q = 0; q < ranks; ++q) {
    send_n[2 * q] = static_cast<std::int64_t>(to[q].size());
    if (with_records) send_n[2 * q + 1] = static_cast<std::int64_t>(records_to[q].size());
  }
  const std::vector<std::int64_t> recv_n = mpi::all_to_all(comm_, send_n, 2);
  Plan plan;
  for (std::size_t q = 0; q < ranks; ++q) {
    const bool quiet = send_n[2 * q] == 0 && send_n[2 * q + 1] == 0 && recv_n[2 * q] == 0 &&
                       recv_n[2 * q + 1] == 0;
    if (static_cast<int>(q) == rank_ || (!all_peers && quiet)) continue;
    plan.peers.push_back(static_cast<int>(q));
    plan.send.push_back(std::move(to[q]));
    plan.recv_count.push_back(static_cast<std::size_t>(recv_n[2 * q]));
    if (!with_records) continue;
    plan.send_records.push_back(std::move(records_to[q]));
    plan.recv_records.push_back(static_cast<std::size_t>(recv_n[2 * q + 1]));
  }
  return plan;
}

void MpiDomain::transport(const Plan& plan, const MessageLayout& layout,
                          const std::vector<std::vector<std::byte>>& send,
                          std::vector<std::vector<std::byte>>& recv) {
  const std::size_t np = plan.peers.size();
  recv.resize(np);
  for (std::size_t u = 0; u < np; ++u) {
    const std::size_t records = plan.recv_records.empty() ? 0 : plan.recv_records[u];
    recv[u].resize(layout.header + plan.recv_count[u] * layout.per_particle +
                   records * layout.per_record);
  }
  mpi::exchange_bytes(comm_, plan.peers, send, recv, requests_);
}

// Migration moves the particles that left this rank's region, with every registered field and
// the contact histories that involve them, through the halo's plan-and-transport: a plan per
// migration (make_plan), one message per peer (the particles field by field, then their
// records), the arrivals appended in ascending rank order and put in id order, so the store is
// the same whatever rank a particle came from: a store in id order stays in id order; one in
// spatial order (core/fast/spatial_order.hpp) keeps the order of the particles that stay, with the
// arrivals after them (the next sort puts them in place).
void MpiDomain::migrate(ParticleStore& p, HistoryRecords& histories) {
  CommTimer timer(stats_.comm_seconds);
  p.clear_ghosts();
  const bool repartitioned = repartition_due_;
  if (repartitioned) repartition(p);
  const std::vector<int> owner = new_owners(p, repartitioned);
  std::vector<char> leaving(p.n_owned(), 0);
  for (std::size_t k = 0; k < p.n_owned(); ++k) leaving[k] = owner[k] != rank_ ? 1 : 0;
  stats_.migrated += std::count(leaving.begin(), leaving.end(), char{1});

  const Plan plan = migration_plan(p, histories, owner);
  pack_migration(p, histories, plan);
  transport(plan, {0, p.bytes_per_particle(), histories.record_bytes()}, send_buffers_,
            recv_buffers_);
  particle_work_.clear();  // indexed by the old store order
  const bool id_order = std::is_sorted(p.id.data(), p.id.data() + p.n_owned());
  p.remove_if(leaving);
  const std::size_t staying = p.n_owned();
  unpack_migration(p, histories, plan);
  sort_owned_by_id(p, id_order ? 0 : staying);
  histories.sort_unique();

  const std::int64_t total = sum(static_cast<std::int64_t>(p.n_owned()));
  if (total != total_particles_) {
    std::ostringstream o;
    o << "migration lost or duplicated particles: " << total << " owned after it, "
      << total_particles_ << " before (rank count " << size_ << ")";
    throw std::logic_error(o.str());
  }
}

std::vector<int> MpiDomain::new_owners(const ParticleStore& p, bool repartitioned) const {
  std::vector<int> owner(p.n_owned());
  std::ostringstream error;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    owner[k] = owner_of(p.pos[k]);
    // Without a repartition a particle leaves only by crossing into a neighbour's wedge: it
    // was a ghost there if it is still within the halo width of this rank's wedge.
    if (owner[k] == rank_ || repartitioned || error.tellp() != 0) continue;
    const double d =
        distance_to_wedge(p.pos[k], options_.center, wedge_begin_[rank_], wedge_end_[rank_]);
    if (d > halo_width_)
      error << "particle " << p.id[k] << " moved " << d << " m beyond the region of rank " << rank_
            << " between two neighbour rebuilds (more than the halo width " << halo_width_
            << " m): the time step is far too large or the particle left the scene";
  }
  mpi::agree_on_failure(comm_, error.str());
  return owner;
}

// Per destination rank: the leaving particles, and every record that involves one of them (a
// record whose two particles leave for different ranks goes to both).
MpiDomain::Plan MpiDomain::migration_plan(const ParticleStore& p, const HistoryRecords& histories,
                                          const std::vector<int>& owner) const {
  const std::size_t ranks = static_cast<std::size_t>(size_);
  std::vector<std::vector<std::int32_t>> to(ranks);
  std::vector<std::vector<std::size_t>> records_to(ranks);
  std::unordered_map<std::int64_t, int> owner_of_leaving;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    if (owner[k] == rank_) continue;
    to[static_cast<std::size_t>(owner[k])].push_back(static_cast<std::int32_t>(k));
    owner_of_leaving.emplace(p.id[k], owner[k]);
  }
  const auto new_owner = [&](std::int64_t id) {
    const auto it = owner_of_leaving.find(id);
    return it == owner_of_leaving.end() ? -1 : it->second;
  };
  for (std::size_t r = 0; r < histories.size(); ++r) {
    const int da = new_owner(histories.a(r));
    const int db = histories.b(r) >= 0 ? new_owner(histories.b(r)) : -1;
    if (da >= 0) records_to[static_cast<std::size_t>(da)].push_back(r);
    if (db >= 0 && db != da) records_to[static_cast<std::size_t>(db)].push_back(r);
  }
  return make_plan(std::move(to), std::move(records_to), /*all_peers=*/false);
}

void MpiDomain::pack_migration(const ParticleStore& p, const HistoryRecords& histories,
                               const Plan& plan) {
  const std::size_t np = plan.peers.size();
  send_buffers_.resize(np);
  for (std::size_t u = 0; u < np; ++u) {
    std::vector<std::byte>& buffer = send_buffers_[u];
    buffer.resize(plan.send[u].size() * p.bytes_per_particle() +
                  plan.send_records[u].size() * histories.record_bytes());
    // Field by field, as the halo packs (one virtual call per field).
    std::byte* out = buffer.data();
    for (const FieldBase* f : p.fields()) out = f->pack_items(plan.send[u], out);
    for (const std::size_t r : plan.send_records[u]) out = histories.pack(r, out);
  }
}

void MpiDomain::unpack_migration(ParticleStore& p, HistoryRecords& histories,
                                 const Plan& plan) const {
  std::size_t arriving = 0;
  for (const std::size_t c : plan.recv_count) arriving += c;
  std::size_t slot = p.add_owned(arriving);
  for (std::size_t u = 0; u < plan.peers.size(); ++u) {
    const std::byte* in = recv_buffers_[u].data();
    for (FieldBase* f : p.fields()) in = f->unpack_items(slot, plan.recv_count[u], in);
    slot += plan.recv_count[u];
    histories.unpack_append(in, plan.recv_records[u] * histories.record_bytes());
  }
}

void MpiDomain::exchange_halo(ParticleStore& p) {
  CommTimer timer(stats_.comm_seconds);
  p.clear_ghosts();
  // Who needs which of my particles: every other rank whose wedge is within the halo width.
  std::vector<std::vector<std::int32_t>> to(static_cast<std::size_t>(size_));
  for (std::size_t k = 0; k < p.n_owned(); ++k)
    for (int q = 0; q < size_; ++q)
      if (q != rank_ && distance_to_wedge(p.pos[k], options_.center, wedge_begin_[q],
                                          wedge_end_[q]) < halo_width_)
        to[static_cast<std::size_t>(q)].push_back(static_cast<std::int32_t>(k));
  all_peers_ = size_ <= kAllPeersRanks;
  halo_ = make_plan(std::move(to), {}, all_peers_);
  halo_sources_.clear();
  for (const auto& list : halo_.send)
    halo_sources_.insert(halo_sources_.end(), list.begin(), list.end());
  std::sort(halo_sources_.begin(), halo_sources_.end());
  halo_sources_.erase(std::unique(halo_sources_.begin(), halo_sources_.end()), halo_sources_.end());
  std::size_t n_ghost = 0;
  for (std::size_t c : halo_.recv_count) n_ghost += c;
  p.add_ghosts(n_ghost);
  fill_ghosts(p, p.fields(), p.fields());
  stats_.ghosts = static_cast<std::int64_t>(n_ghost);
}

void MpiDomain::refresh_ghosts(ParticleStore& p, std::span<FieldBase* const> fields) {
  if (halo_.peers.empty()) return;  // one rank, or no neighbour within the halo
  CommTimer timer(stats_.comm_seconds);
  fill_ghosts(p, fields, fields);
}

void MpiDomain::exchange_step(ParticleStore& p, std::span<FieldBase* const> send_fields,
                              std::span<FieldBase* const> recv_fields, std::span<double> values) {
  if (size_ == 1) return;
  CommTimer timer(stats_.comm_seconds);
  if (all_peers_) {
    fill_ghosts(p, send_fields, recv_fields, values);
    return;
  }
  fill_ghosts(p, send_fields, recv_fields);
  // A NaN must win on every rank, and MPI_MAX may drop it: it travels as a flag beside the value.
  const std::size_t n = values.size();
  std::vector<double>& both = reduce_buffer_;  // kept between steps
  both.resize(2 * n);
  for (std::size_t v = 0; v < n; ++v) {
    const bool nan = std::isnan(values[v]);
    both[v] = nan ? -std::numeric_limits<double>::infinity() : values[v];
    both[n + v] = nan ? 1.0 : 0.0;
  }
  max(both);
  for (std::size_t v = 0; v < n; ++v) values[v] = both[n + v] > 0.0 ? std::nan("") : both[v];
}

void MpiDomain::fill_ghosts(ParticleStore& p, std::span<FieldBase* const> send_fields,
                            std::span<FieldBase* const> recv_fields, std::span<double> values) {
  std::size_t bpi = 0;
  for (const FieldBase* f : send_fields) bpi += f->bytes_per_item();
  const std::size_t header = values.size_bytes();
  const std::size_t np = halo_.peers.size();
  // Buffers kept between calls: the halo refresh runs every step.
  std::vector<std::vector<std::byte>>& send = send_buffers_;
  std::vector<std::vector<std::byte>>& recv = recv_buffers_;
  send.resize(np);
  for (std::size_t u = 0; u < np; ++u) {
    send[u].resize(header + halo_.send[u].size() * bpi);
    if (header) std::memcpy(send[u].data(), values.data(), header);
    // Field by field (one virtual call each), not particle by particle.
    std::byte* out = send[u].data() + header;
    for (const FieldBase* f : send_fields) out = f->pack_items(halo_.send[u], out);
  }
  transport(halo_, {header, bpi, 0}, send, recv);
  std::size_t slot = p.n_owned();
  for (std::size_t u = 0; u < np; ++u) {
    const std::byte* in = recv[u].data();
    for (std::size_t v = 0; v < values.size(); ++v) {
      double theirs;
      std::memcpy(&theirs, in + v * sizeof(double), sizeof(double));
      // Order-independent maximum that keeps a NaN from any rank.
      if (std::isnan(theirs) || theirs > values[v])
        values[v] = std::isnan(values[v]) ? values[v] : theirs;
    }
    in += header;
    for (FieldBase* f : recv_fields) in = f->unpack_items(slot, halo_.recv_count[u], in);
    slot += halo_.recv_count[u];
  }
}

}  // namespace dem2d
