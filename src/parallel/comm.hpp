// Every MPI call of dem2d, as small verbs over a communicator (docs/architecture.md, "Code
// conventions"; CoMD's parallel.c keeps all of its MPI in one file for the same reason). MpiDomain
// builds the decomposition on these; src/io uses them for its collective decisions (row offsets of
// a snapshot, agreeing on a failure) and takes only the MPI_Comm handle itself, which parallel HDF5
// needs (H5Pset_fapl_mpio); src/app calls nothing but mpi::init, MPI_Comm_rank, MPI_Comm_size and
// MPI_Finalize (tests/structure/check_layers.sh checks both).
//
// Every function is collective over `comm` unless it says otherwise: all ranks call it, in
// the same order. Reductions of doubles that feed the physics are exact (max) or added in
// rank order (all_gather, then a sum), never left to MPI's reduction order.
#pragma once

#include <mpi.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace dem2d::mpi {

// MPI_Init, after choosing the MPI-IO component that the HDF5 files are written with. Open
// MPI's default one (OMPIO) opens every file with a shared file pointer kept under a named
// POSIX semaphore, /dev/shm/sem.OMPIO_<file name>, locked and released inside MPI_File_open.
// A run killed inside that window (kill -9, a batch system's time limit) leaves it locked, and
// from then on every open of a file of that name, in any directory, waits forever. dem2d uses
// no shared file pointer, so it leaves OMPIO out (OMPI_MCA_io=^ompio): Open MPI then uses its
// ROMIO, which creates nothing
// beside the file. A user's own OMPI_MCA_io is kept. Other MPI libraries ignore the variable.
void init(int* argc, char*** argv);

// Not collective: this process's rank and the number of ranks.
int rank(MPI_Comm comm);
int size(MPI_Comm comm);
// Not collective: seconds of wall time since some fixed point (MPI_Wtime).
double wall_time();

// Not collective: MPI-IO hints for the files HDF5 writes (an MPI_Info the holder frees). ROMIO's
// data sieving is off: the small pieces of an HDF5 file's metadata are written as they are, not
// as a read-modify-write of a 512 KiB window around them.
class IoHints {
 public:
  IoHints();
  ~IoHints();
  IoHints(const IoHints&) = delete;
  IoHints& operator=(const IoHints&) = delete;
  MPI_Info get() const { return info_; }

 private:
  MPI_Info info_ = MPI_INFO_NULL;
};

// Sums of integers (exact in any order).
std::int64_t sum(MPI_Comm comm, std::int64_t x);
std::uint64_t sum(MPI_Comm comm, std::uint64_t x);
// The sum of `x` over the ranks below this one: 0 on rank 0 (MPI_Exscan leaves it undefined).
std::uint64_t exclusive_scan_sum(MPI_Comm comm, std::uint64_t x);
// Element-wise sum in place. Exact only when every partial sum is (e.g. multiples of 1/2).
void sum_in_place(MPI_Comm comm, std::span<double> values);
void sum_in_place(MPI_Comm comm, std::span<std::int64_t> values);
// Maximum, element-wise maximum in place, logical or: exact.
double max(MPI_Comm comm, double x);
void max_in_place(MPI_Comm comm, std::span<double> values);
bool any(MPI_Comm comm, bool x);
// Every rank's `x`, in rank order, on every rank.
std::vector<double> all_gather(MPI_Comm comm, double x);
// Every rank's values (any count per rank), concatenated in rank order, on every rank.
std::vector<std::int64_t> all_gather(MPI_Comm comm, std::span<const std::int64_t> mine);
// `values` (the same length on every rank) from `root`, in place.
void broadcast(MPI_Comm comm, std::span<int> values, int root);
// `root`'s string on every rank (the others' argument is ignored).
std::string broadcast_string(MPI_Comm comm, const std::string& s, int root);
// `send` holds `per_rank` values for each rank q at [q * per_rank, (q + 1) * per_rank);
// returns what every rank sent to this one, laid out the same way (MPI_Alltoall).
std::vector<std::int64_t> all_to_all(MPI_Comm comm, std::span<const std::int64_t> send,
                                     std::size_t per_rank);

// Point to point, collective over the listed peers only: sends send[u] to peers[u] and
// receives recv[u] from peers[u], whose size the caller has set (both sides know every
// message's size). Empty messages are not sent. `requests` is scratch kept by the caller.
void exchange_bytes(MPI_Comm comm, std::span<const int> peers,
                    const std::vector<std::vector<std::byte>>& send,
                    std::vector<std::vector<std::byte>>& recv, std::vector<MPI_Request>& requests);

// Agreeing on a failure (docs/architecture.md, "Code conventions": never a throw on one rank that
// leaves the others waiting in a collective). `local_error` is this rank's failure message, empty
// if it succeeded. Returns, on every rank, the message of the lowest failing rank, or an empty
// string when no rank failed.
std::string first_failure(MPI_Comm comm, const std::string& local_error);

// The one "agree on failure" of dem2d: when any rank failed, every rank throws Error with the
// lowest failing rank's message, so all ranks report the same text and exit alike; otherwise
// it returns on every rank. MpiDomain throws std::runtime_error (the Domain contract), io
// throws IoError (exit status 4).
template <class Error = std::runtime_error>
void agree_on_failure(MPI_Comm comm, const std::string& local_error) {
  const std::string message = first_failure(comm, local_error);
  if (!message.empty()) throw Error(message);
}

}  // namespace dem2d::mpi
