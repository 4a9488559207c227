#include "parallel/mpi_domain.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace dem2d {

namespace {

constexpr int kTagHalo = 7301;

// Wall-clock accumulator for the time spent communicating.
class CommTimer {
 public:
  explicit CommTimer(double& total) : total_(total), start_(MPI_Wtime()) {}
  ~CommTimer() { total_ += MPI_Wtime() - start_; }

 private:
  double& total_;
  double start_;
};

// Item i of each field, one after the other (migration: every field of a particle together).
std::byte* pack_fields(std::span<FieldBase* const> fields, std::size_t i, std::byte* out) {
  for (const FieldBase* f : fields) {
    f->pack(i, out);
    out += f->bytes_per_item();
  }
  return out;
}

const std::byte* unpack_fields(std::span<FieldBase* const> fields, std::size_t i,
                               const std::byte* in) {
  for (FieldBase* f : fields) {
    f->unpack(i, in);
    in += f->bytes_per_item();
  }
  return in;
}

}  // namespace

MpiDomain::MpiDomain(MPI_Comm comm, const DecompositionOptions& options)
    : comm_(comm), options_(options) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  if (options_.sectors_per_rank < 1) options_.sectors_per_rank = 1;
  partition_ = partition_equal_angle(options_.sectors_per_rank * size_, size_);
  rebuild_wedges();
}

// Sum in rank order on every rank: an MPI_Allreduce may add in any order.
double MpiDomain::sum(double x) const {
  if (size_ == 1) return x;  // one rank: no MPI call in the step loop
  std::vector<double> all(size_);
  MPI_Allgather(&x, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, comm_);
  double s = 0.0;
  for (double v : all) s += v;
  return s;
}

double MpiDomain::max(double x) const {
  if (size_ == 1) return x;
  double r = 0.0;
  MPI_Allreduce(&x, &r, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return r;
}

std::int64_t MpiDomain::sum(std::int64_t x) const {
  if (size_ == 1) return x;
  std::int64_t r = 0;
  MPI_Allreduce(&x, &r, 1, MPI_INT64_T, MPI_SUM, comm_);
  return r;
}

void MpiDomain::max(std::span<double> values) const {
  if (size_ == 1 || values.empty()) return;
  MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_MAX,
                comm_);
}

bool MpiDomain::any(bool x) const {
  if (size_ == 1) return x;
  int in = x ? 1 : 0, out = 0;
  MPI_Allreduce(&in, &out, 1, MPI_INT, MPI_LOR, comm_);
  return out != 0;
}

void MpiDomain::agree(const std::string& local_error) const {
  // The lowest failing rank's message, on every rank.
  const int mine = local_error.empty() ? size_ : rank_;
  int first = size_;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm_);
  if (first == size_) return;
  int len = first == rank_ ? static_cast<int>(local_error.size()) : 0;
  MPI_Bcast(&len, 1, MPI_INT, first, comm_);
  std::string msg(static_cast<std::size_t>(len), ' ');
  if (first == rank_) msg = local_error;
  MPI_Bcast(msg.data(), len, MPI_CHAR, first, comm_);
  throw std::runtime_error(msg);
}

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
  std::vector<double> total(weights.size());
  MPI_Allreduce(weights.data(), total.data(), static_cast<int>(total.size()), MPI_DOUBLE, MPI_SUM,
                comm_);
  const std::span<const double> work(total.data(), static_cast<std::size_t>(n));
  const std::span<const double> edges(total.data() + n, static_cast<std::size_t>(n));
  std::vector<int> owner(static_cast<std::size_t>(n));
  std::string method;
  if (rank_ == 0) {
    const SectorPartition part = partition_metis(work, edges, size_);
    owner = part.owner;
    method = part.method;
  }
  MPI_Bcast(owner.data(), n, MPI_INT, 0, comm_);
  int len = static_cast<int>(method.size());
  MPI_Bcast(&len, 1, MPI_INT, 0, comm_);
  method.resize(static_cast<std::size_t>(len));
  MPI_Bcast(method.data(), len, MPI_CHAR, 0, comm_);
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
  double in[2] = {work, -work}, out[2] = {0.0, 0.0};
  MPI_Allreduce(in, out, 2, MPI_DOUBLE, MPI_MAX, comm_);
  const double total = sum(work);
  const double mean = total / size_;
  stats_.imbalance_work = mean > 0.0 ? out[0] / mean : 1.0;
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

std::vector<double> MpiDomain::gather_work() const {
  std::vector<double> all(static_cast<std::size_t>(size_));
  MPI_Allgather(&stats_.work, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, comm_);
  return all;
}

void MpiDomain::migrate(ParticleStore& p, HistoryRecords& histories) {
  CommTimer timer(stats_.comm_seconds);
  p.clear_ghosts();
  const bool repartitioned = repartition_due_;
  if (repartitioned) repartition(p);
  const std::size_t n = p.n_owned();
  std::vector<int> dest(n);
  std::vector<char> leaving(n, 0);
  std::ostringstream error;
  for (std::size_t k = 0; k < n; ++k) {
    dest[k] = owner_of(p.pos[k]);
    if (dest[k] == rank_) continue;
    leaving[k] = 1;
    // Without a repartition a particle leaves only by crossing into a neighbour's wedge: it
    // was a ghost there if it is still within the halo width of this rank's wedge.
    if (!repartitioned && error.tellp() == 0) {
      const double d =
          distance_to_wedge(p.pos[k], options_.center, wedge_begin_[rank_], wedge_end_[rank_]);
      if (d > halo_width_)
        error << "particle " << p.id[k] << " moved " << d << " m beyond the region of rank "
              << rank_ << " between two neighbour rebuilds (more than the halo width "
              << halo_width_
              << " m): the time step is far too large or the particle left the scene";
    }
  }
  agree(error.str());

  // Particles and their histories, per destination rank.
  const std::size_t bpp = p.bytes_per_particle();
  std::vector<std::vector<std::byte>> send_particles(static_cast<std::size_t>(size_));
  std::vector<std::vector<std::byte>> send_records(static_cast<std::size_t>(size_));
  std::unordered_map<std::int64_t, int> dest_of_leaving;
  for (std::size_t k = 0; k < n; ++k) {
    if (!leaving[k]) continue;
    auto& buf = send_particles[static_cast<std::size_t>(dest[k])];
    const std::size_t at = buf.size();
    buf.resize(at + bpp);
    pack_fields(p.fields(), k, buf.data() + at);
    dest_of_leaving.emplace(p.id[k], dest[k]);
  }
  const std::size_t record_bytes = histories.record_bytes();
  const auto send_record = [&](int q, std::size_t r) {
    auto& buf = send_records[static_cast<std::size_t>(q)];
    buf.resize(buf.size() + record_bytes);
    histories.pack(r, buf.data() + buf.size() - record_bytes);
  };
  for (std::size_t r = 0; r < histories.size(); ++r) {
    int da = -1, db = -1;
    if (auto it = dest_of_leaving.find(histories.a(r)); it != dest_of_leaving.end())
      da = it->second;
    if (histories.b(r) >= 0)
      if (auto it = dest_of_leaving.find(histories.b(r)); it != dest_of_leaving.end())
        db = it->second;
    if (da >= 0) send_record(da, r);
    if (db >= 0 && db != da) send_record(db, r);
  }
  stats_.migrated += static_cast<std::int64_t>(dest_of_leaving.size());

  // Counts, then the bytes (particles and records in one all-to-all each).
  const auto exchange = [&](const std::vector<std::vector<std::byte>>& out) {
    std::vector<long long> send_n(static_cast<std::size_t>(size_)),
        recv_n(static_cast<std::size_t>(size_));
    for (int q = 0; q < size_; ++q)
      send_n[static_cast<std::size_t>(q)] =
          static_cast<long long>(out[static_cast<std::size_t>(q)].size());
    MPI_Alltoall(send_n.data(), 1, MPI_LONG_LONG, recv_n.data(), 1, MPI_LONG_LONG, comm_);
    std::vector<int> sc(static_cast<std::size_t>(size_)), sd(static_cast<std::size_t>(size_)),
        rc(static_cast<std::size_t>(size_)), rd(static_cast<std::size_t>(size_));
    std::vector<std::byte> flat_send, flat_recv;
    for (int q = 0; q < size_; ++q) {
      const std::size_t u = static_cast<std::size_t>(q);
      sd[u] = static_cast<int>(flat_send.size());
      sc[u] = static_cast<int>(send_n[u]);
      flat_send.insert(flat_send.end(), out[u].begin(), out[u].end());
    }
    std::size_t total = 0;
    for (int q = 0; q < size_; ++q) {
      const std::size_t u = static_cast<std::size_t>(q);
      rd[u] = static_cast<int>(total);
      rc[u] = static_cast<int>(recv_n[u]);
      total += static_cast<std::size_t>(recv_n[u]);
    }
    flat_recv.resize(total);
    MPI_Alltoallv(flat_send.data(), sc.data(), sd.data(), MPI_BYTE, flat_recv.data(), rc.data(),
                  rd.data(), MPI_BYTE, comm_);
    return flat_recv;
  };
  const std::vector<std::byte> arrived = exchange(send_particles);
  const std::vector<std::byte> arrived_records = exchange(send_records);

  // Drop the leavers, append the arrivals, keep the owned particles in id order.
  particle_work_.clear();  // indexed by the old store order
  p.remove_if(leaving);
  const std::size_t n_new = arrived.size() / bpp;
  const std::size_t first = p.add_owned(n_new);
  for (std::size_t k = 0; k < n_new; ++k)
    unpack_fields(p.fields(), first + k, arrived.data() + k * bpp);
  if (!std::is_sorted(p.id.data(), p.id.data() + p.n_owned())) {
    std::vector<std::size_t> order(p.n_owned());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::sort(order.begin(), order.end(),
              [&](std::size_t a, std::size_t b) { return p.id[a] < p.id[b]; });
    p.permute(order);
  }
  histories.unpack_append(arrived_records.data(), arrived_records.size());
  histories.sort_unique();

  const std::int64_t total = sum(static_cast<std::int64_t>(p.n_owned()));
  if (total != total_particles_) {
    std::ostringstream o;
    o << "migration lost or duplicated particles: " << total << " owned after it, "
      << total_particles_ << " before (rank count " << size_ << ")";
    throw std::logic_error(o.str());
  }
}

void MpiDomain::transport(const Plan& plan, std::size_t header_bytes, std::size_t bytes_per_item,
                          const std::vector<std::vector<std::byte>>& send,
                          std::vector<std::vector<std::byte>>& recv) {
  const std::size_t np = plan.peers.size();
  recv.resize(np);
  std::vector<MPI_Request>& req = requests_;
  req.clear();
  req.reserve(2 * np);
  for (std::size_t u = 0; u < np; ++u) {
    recv[u].resize(header_bytes + plan.recv_count[u] * bytes_per_item);
    if (recv[u].empty()) continue;
    req.emplace_back();
    MPI_Irecv(recv[u].data(), static_cast<int>(recv[u].size()), MPI_BYTE, plan.peers[u], kTagHalo,
              comm_, &req.back());
  }
  for (std::size_t u = 0; u < np; ++u) {
    if (send[u].empty()) continue;
    req.emplace_back();
    MPI_Isend(send[u].data(), static_cast<int>(send[u].size()), MPI_BYTE, plan.peers[u], kTagHalo,
              comm_, &req.back());
  }
  MPI_Waitall(static_cast<int>(req.size()), req.data(), MPI_STATUSES_IGNORE);
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
  std::vector<long long> send_n(static_cast<std::size_t>(size_)),
      recv_n(static_cast<std::size_t>(size_));
  for (int q = 0; q < size_; ++q)
    send_n[static_cast<std::size_t>(q)] =
        static_cast<long long>(to[static_cast<std::size_t>(q)].size());
  MPI_Alltoall(send_n.data(), 1, MPI_LONG_LONG, recv_n.data(), 1, MPI_LONG_LONG, comm_);
  halo_ = Plan{};
  all_peers_ = size_ <= kAllPeersRanks;
  for (int q = 0; q < size_; ++q) {
    const std::size_t u = static_cast<std::size_t>(q);
    if (q == rank_ || (!all_peers_ && send_n[u] == 0 && recv_n[u] == 0)) continue;
    halo_.peers.push_back(q);
    halo_.send.push_back(std::move(to[u]));
    halo_.recv_count.push_back(static_cast<std::size_t>(recv_n[u]));
  }
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
  transport(halo_, header, bpi, send, recv);
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
