// The output directory of a run: created, checked and claimed once, before anything is
// written, by all ranks together (docs/architecture.md, "Code conventions"). One folder, one run: a
// run claims its folder with a lock file naming its host and pid, removed when the run ends.
#pragma once

#include <string>

#include "parallel/comm.hpp"

namespace dem2d {

// The lock a run holds on its output directory; rank 0 removes the file when it goes.
class OutputLock {
 public:
  OutputLock() = default;
  explicit OutputLock(std::string path) : path_(std::move(path)) {}
  OutputLock(OutputLock&& o) noexcept : path_(std::move(o.path_)) { o.path_.clear(); }
  OutputLock& operator=(OutputLock&&) = delete;
  OutputLock(const OutputLock&) = delete;
  OutputLock& operator=(const OutputLock&) = delete;
  ~OutputLock();

 private:
  std::string path_;  // empty on ranks other than 0
};

// The files a run writes into its directory (their writers take the names from here), and the
// lock's name.
inline constexpr const char* kRunJsonFile = "run.json";
inline constexpr const char* kSeriesFile = "series.csv";
inline constexpr const char* kSnapshotsFile = "snapshots.h5";
inline constexpr const char* kXdmfFile = "snapshots.xmf";
inline constexpr const char* kProductFile = "product.csv";
inline constexpr const char* kBreakagesFile = "breakages.csv";
inline constexpr const char* kCheckpointFile = "checkpoint.h5";
inline constexpr const char* kCollisionsFile = "collisions.csv";
inline constexpr const char* kRunOutputs[] = {kRunJsonFile,    kSeriesFile,    kSnapshotsFile,
                                              kXdmfFile,       kProductFile,   kBreakagesFile,
                                              kCheckpointFile, kCollisionsFile};
inline constexpr const char* kOutputLockName = ".dem2d.lock";

// Collective. Rank 0 creates `dir` (with its parents), checks that a file can be created and
// removed in it, and claims it for this run:
//   - a folder locked by a dem2d run that is still running (same host, live pid) is refused,
//     --overwrite or not;
//   - a folder holding another run's output (a file of kRunOutputs, or the lock of a run that
//     has ended without removing it) is refused unless `overwrite`, which removes those files;
//   - then the lock is created (exclusively: of two runs starting together one is refused).
// The outcome is broadcast: on failure every rank throws IoError with the same text (the
// reason and what to do: "give ... --output DIR", "--overwrite").
// How a run takes its folder: a new run (refused if it holds another run's output), one that
// replaces that output (--overwrite), or a restart that continues the output there (--restart:
// a killed run's lock is taken over, the output kept).
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

}  // namespace dem2d
