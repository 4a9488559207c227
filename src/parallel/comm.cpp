#include "parallel/comm.hpp"

#include <cstdlib>

namespace dem2d::mpi {

void init(int* argc, char*** argv) {
  setenv("OMPI_MCA_io", "^ompio", /*overwrite=*/0);
  MPI_Init(argc, argv);
}

int rank(MPI_Comm comm) {
  int r = 0;
  MPI_Comm_rank(comm, &r);
  return r;
}

int size(MPI_Comm comm) {
  int s = 1;
  MPI_Comm_size(comm, &s);
  return s;
}

IoHints::IoHints() {
  MPI_Info_create(&info_);
  MPI_Info_set(info_, "romio_ds_write", "disable");
  MPI_Info_set(info_, "romio_ds_read", "disable");
}
IoHints::~IoHints() { MPI_Info_free(&info_); }

double wall_time() { return MPI_Wtime(); }

std::int64_t sum(MPI_Comm comm, std::int64_t x) {
  std::int64_t r = 0;
  MPI_Allreduce(&x, &r, 1, MPI_INT64_T, MPI_SUM, comm);
  return r;
}

std::uint64_t sum(MPI_Comm comm, std::uint64_t x) {
  std::uint64_t r = 0;
  MPI_Allreduce(&x, &r, 1, MPI_UINT64_T, MPI_SUM, comm);
  return r;
}

std::uint64_t exclusive_scan_sum(MPI_Comm comm, std::uint64_t x) {
  std::uint64_t r = 0;
  MPI_Exscan(&x, &r, 1, MPI_UINT64_T, MPI_SUM, comm);
  return rank(comm) == 0 ? 0 : r;
}

void sum_in_place(MPI_Comm comm, std::span<double> values) {
  if (values.empty()) return;
  MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_SUM,
                comm);
}

void sum_in_place(MPI_Comm comm, std::span<std::int64_t> values) {
  if (values.empty()) return;
  MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_INT64_T, MPI_SUM,
                comm);
}

double max(MPI_Comm comm, double x) {
  double r = 0.0;
  MPI_Allreduce(&x, &r, 1, MPI_DOUBLE, MPI_MAX, comm);
  return r;
}

void max_in_place(MPI_Comm comm, std::span<double> values) {
  if (values.empty()) return;
  MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_MAX,
                comm);
}

bool any(MPI_Comm comm, bool x) {
  int in = x ? 1 : 0, out = 0;
  MPI_Allreduce(&in, &out, 1, MPI_INT, MPI_LOR, comm);
  return out != 0;
}

std::vector<double> all_gather(MPI_Comm comm, double x) {
  std::vector<double> all(static_cast<std::size_t>(size(comm)));
  MPI_Allgather(&x, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, comm);
  return all;
}

std::vector<std::int64_t> all_gather(MPI_Comm comm, std::span<const std::int64_t> mine) {
  const int n = size(comm);
  std::vector<int> counts(static_cast<std::size_t>(n)), offsets(static_cast<std::size_t>(n), 0);
  const int count = static_cast<int>(mine.size());
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (std::size_t r = 1; r < counts.size(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<std::int64_t> all(static_cast<std::size_t>(offsets.back() + counts.back()));
  MPI_Allgatherv(mine.data(), count, MPI_INT64_T, all.data(), counts.data(), offsets.data(),
                 MPI_INT64_T, comm);
  return all;
}

void broadcast(MPI_Comm comm, std::span<int> values, int root) {
  if (values.empty()) return;
  MPI_Bcast(values.data(), static_cast<int>(values.size()), MPI_INT, root, comm);
}

std::string broadcast_string(MPI_Comm comm, const std::string& s, int root) {
  const bool is_root = rank(comm) == root;
  std::uint64_t length = is_root ? s.size() : 0;
  MPI_Bcast(&length, 1, MPI_UINT64_T, root, comm);
  std::string out = is_root ? s : std::string(static_cast<std::size_t>(length), '\0');
  if (length > 0) MPI_Bcast(out.data(), static_cast<int>(length), MPI_CHAR, root, comm);
  return out;
}

std::vector<std::int64_t> all_to_all(MPI_Comm comm, std::span<const std::int64_t> send,
                                     std::size_t per_rank) {
  std::vector<std::int64_t> recv(send.size());
  MPI_Alltoall(send.data(), static_cast<int>(per_rank), MPI_INT64_T, recv.data(),
               static_cast<int>(per_rank), MPI_INT64_T, comm);
  return recv;
}

void exchange_bytes(MPI_Comm comm, std::span<const int> peers,
                    const std::vector<std::vector<std::byte>>& send,
                    std::vector<std::vector<std::byte>>& recv, std::vector<MPI_Request>& requests) {
  // One tag for every round: a round completes (Waitall) before the next starts on this rank,
  // and MPI does not let messages between two ranks overtake each other, so a message always
  // meets the receive of its own round.
  constexpr int kTag = 7301;
  requests.clear();
  requests.reserve(2 * peers.size());
  for (std::size_t u = 0; u < peers.size(); ++u) {
    if (recv[u].empty()) continue;
    requests.emplace_back();
    MPI_Irecv(recv[u].data(), static_cast<int>(recv[u].size()), MPI_BYTE, peers[u], kTag, comm,
              &requests.back());
  }
  for (std::size_t u = 0; u < peers.size(); ++u) {
    if (send[u].empty()) continue;
    requests.emplace_back();
    MPI_Isend(send[u].data(), static_cast<int>(send[u].size()), MPI_BYTE, peers[u], kTag, comm,
              &requests.back());
  }
  MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE);
}

std::string first_failure(MPI_Comm comm, const std::string& local_error) {
  const int n = size(comm);
  const int mine = local_error.empty() ? n : rank(comm);
  int first = n;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == n) return {};
  return broadcast_string(comm, local_error, first);
}

}  // namespace dem2d::mpi
