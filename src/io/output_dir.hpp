// The output directory of a run: created, checked and claimed once, before anything is
// written, by all ranks together (docs/architecture.md, "Code conventions"). One folder, one run: a
// run claims its folder with a lock file naming its host and pid, removed when the run ends.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

#include "parallel/comm.hpp"

namespace dem2d {

// The lock a run holds on its output directory: on rank 0, the lock file, open and locked
// (flock) while the run lasts; the file is removed when the run ends.
class OutputLock {
 public:
  OutputLock() = default;
  OutputLock(std::string path, int fd) : path_(std::move(path)), fd_(fd) {}
  OutputLock(OutputLock&& o) noexcept : path_(std::move(o.path_)), fd_(o.fd_) { o.fd_ = -1; }
  OutputLock& operator=(OutputLock&&) = delete;
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;
  ~OutputLock();

 private:
  std::string path_;
  int fd_ = -1;  // -1 on ranks other than 0
};

// The files a run writes into its directory (their writers take the names from here), and the
// lock's name.
inline constexpr const char* kRunJsonFile = "run.json";
inline constexpr const char* kSeriesFile = "series.csv";
inline constexpr const char* kSnapshotsFile = "snapshots.h5";
inline constexpr const char* kXdmfFile = "snapshots.xmf";
inline constexpr const char* kProductFile = "product.csv";
inline constexpr const char* kBreakagesFile = "breakages.csv";
inline constexpr const char* kFragmentsFile = "fragments.csv";
inline constexpr const char* kSizesFile = "sizes.csv";
inline constexpr const char* kCheckpointFile = "checkpoint.h5";
inline constexpr const char* kCollisionsFile = "collisions.csv";
inline constexpr const char* kLiftersFile = "lifters.csv";
inline constexpr const char* kRunOutputs[] = {
    kRunJsonFile,   kSeriesFile, kSnapshotsFile,  kXdmfFile,       kProductFile, kBreakagesFile,
    kFragmentsFile, kSizesFile,  kCheckpointFile, kCollisionsFile, kLiftersFile};
inline constexpr const char* kOutputLockName = ".dem2d.lock";

// Collective. Rank 0 creates `dir` (with its parents), checks that a file can be created and
// removed in it, and claims it for this run:
//   - a folder whose lock file a running dem2d holds locked is refused, --overwrite or not (the
//     message names the lock file and that run's pid); a lock file nobody holds is a dead run's
//     and is taken over (a one-line notice on stderr), whatever pid it names;
//   - a folder holding another run's output (a file of kRunOutputs, or the lock of a run on
//     another host, which this host cannot check) is refused unless `overwrite`, which removes
//     those files; with a checkpoint there, the message offers --restart first;
//   - then the lock is taken (of two runs starting together one is refused).
// The outcome is broadcast: on failure every rank throws IoError with the same text (the
// reason and what to do: "give ... --output DIR", "--overwrite", "--restart").
enum class Claim { kNew, kOverwrite, kContinue };
OutputLock claim_output_directory(MPI_Comm comm, const std::string& dir, Claim how);

// Collective, before a collective HDF5 write of about `bytes` to `path`: rank 0 checks the free
// space of the file system that holds it (statvfs) and every rank throws the same IoError
// "cannot write PATH: No space left on device (...)" when less than twice `bytes` is free.
// Parallel HDF5 cannot recover from a write that fails on one rank and not on the others (the
// ranks would wait for each other in different collectives), so a disk that fills is stopped
// here, before the write; the files written so far stay whole.
void ensure_free_space(MPI_Comm comm, const std::string& path, std::uint64_t bytes);

// Writes `text` to `path` through a temporary file and a rename, so that a reader never sees
// a half-written file (snapshots.xmf, collisions.csv). Returns an error message, empty on
// success.
std::string write_file_atomically(const std::string& path, const std::string& text);

// Appends `text` to the open log `f` (series.csv, lifters.csv, the ore logs) and flushes it, so
// that the rows written are on disk if the run stops; an IoError naming `path` and the system's
// reason when the write or the flush fails.
void append_to_log(std::FILE* f, const std::string& path, std::string_view text);

}  // namespace dem2d
