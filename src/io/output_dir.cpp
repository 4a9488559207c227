#include "io/output_dir.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <vector>

#include "core/base/errors.hpp"
#include "parallel/comm.hpp"

namespace dem2d {
namespace {

namespace fs = std::filesystem;

// Creates `dir` and probes it; returns the reason it is unusable, empty if it is fine.
std::string check_directory(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return ec.message();
  if (!fs::is_directory(dir, ec)) return ec ? ec.message() : "not a directory";
  const fs::path probe = dir / fmt::format(".dem2d-write-test-{}", ::getpid());
  std::FILE* f = std::fopen(probe.c_str(), "wb");
  if (f == nullptr) return std::strerror(errno);
  const bool written = std::fputc('\n', f) != EOF;
  const int write_errno = errno;
  const bool closed = std::fclose(f) == 0;
  const int close_errno = errno;
  fs::remove(probe, ec);
  if (!written) return std::strerror(write_errno);
  if (!closed) return std::strerror(close_errno);
  if (ec) return ec.message();
  return {};
}

std::string this_host() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return "unknown";
  return name;
}

// Who holds a lock: "HOST PID" as the lock file says it.
struct LockHolder {
  std::string host;
  long pid = 0;
  bool running_here = false;  // on this host and the process is alive
};

// A process that has ended but not been reaped yet (state Z in /proc/PID/stat) still answers
// kill(pid, 0): it is not running.
bool is_zombie(long pid) {
  std::ifstream stat(fmt::format("/proc/{}/stat", pid));
  std::string line;
  if (!std::getline(stat, line)) return false;
  const std::size_t close = line.rfind(')');  // the name in parentheses may hold spaces
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] == 'Z';
}

LockHolder read_lock(const fs::path& lock, const std::string& host) {
  LockHolder h;
  std::ifstream in(lock);
  in >> h.host >> h.pid;
  if (h.host == host && h.pid > 0)
    h.running_here =
        (::kill(static_cast<pid_t>(h.pid), 0) == 0 || errno == EPERM) && !is_zombie(h.pid);
  return h;
}

// Takes the lock (exclusively: of two runs starting together one is refused); returns the reason
// it could not, empty once the lock file holds "HOST PID".
std::string take_lock(const fs::path& lock, const std::string& shown, const std::string& host) {
  const int fd = ::open(lock.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
  if (fd < 0 && errno == EEXIST)
    return fmt::format(
        "output directory '{}' was claimed by another dem2d run starting at the "
        "same time; give this run its own folder with --output DIR",
        shown);
  if (fd < 0)
    return fmt::format("cannot write to output directory '{}': {}", shown, std::strerror(errno));
  const std::string text = fmt::format("{} {}\n", host, ::getpid());
  const bool written = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  ::close(fd);
  if (written) return {};
  std::error_code ec;
  fs::remove(lock, ec);
  return fmt::format("cannot write to output directory '{}': {}", shown, "disk full");
}

// The claim's verdict on rank 0: empty when the folder is this run's now (its lock taken).
std::string claim(const fs::path& dir, const std::string& shown, Claim how) {
  if (const std::string reason = check_directory(dir); !reason.empty())
    return fmt::format(
        "cannot write to output directory '{}': {}; give a directory you can "
        "write to",
        shown, reason);
  const std::string host = this_host();
  const fs::path lock = dir / kOutputLockName;
  std::error_code ec;
  std::vector<std::string> found;
  if (fs::exists(lock, ec)) {
    const LockHolder h = read_lock(lock, host);
    if (h.running_here)
      return fmt::format(
          "output directory '{}' is in use by a dem2d run that is still running "
          "(pid {} on host {}); give this run its own folder with --output DIR",
          shown, h.pid, h.host);
    found.push_back(h.host == host
                        ? fmt::format("{} of a run that did not end (pid {} on host {})",
                                      kOutputLockName, h.pid, h.host)
                        : fmt::format("{} of a run on host {} (pid {}), which may still be "
                                      "running: this host cannot tell",
                                      kOutputLockName, h.host, h.pid));
  }
  for (const char* name : kRunOutputs)
    if (fs::exists(dir / name, ec)) found.emplace_back(name);
  if (!found.empty() && how == Claim::kNew)
    return fmt::format(
        "output directory '{}' holds another run's output ({}); give this run a "
        "new folder with --output DIR, or --overwrite to replace that output",
        shown, fmt::join(found, ", "));
  fs::remove(lock, ec);
  if (how == Claim::kOverwrite)
    for (const char* name : kRunOutputs) fs::remove(dir / name, ec);
  return take_lock(lock, shown, host);
}

}  // namespace

void ensure_free_space(MPI_Comm comm, const std::string& path, std::uint64_t bytes) {
  std::string error;
  if (mpi::rank(comm) == 0) {
    const fs::path file(path);
    const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
    struct statvfs st {};
    if (::statvfs(dir.c_str(), &st) == 0) {
      const auto free = static_cast<std::uint64_t>(st.f_bavail) * st.f_frsize;
      if (free < 2 * bytes)
        error = fmt::format(
            "cannot write {}: No space left on device ({} kB free, the write needs about {} kB "
            "and dem2d keeps as much again in reserve)",
            path, free / 1024, (bytes + 1023) / 1024);
    }
  }
  mpi::agree_on_failure<IoError>(comm, error);
}

OutputLock::~OutputLock() {
  if (path_.empty()) return;
  std::error_code ec;
  fs::remove(path_, ec);
}

OutputLock claim_output_directory(MPI_Comm comm, const std::string& dir, Claim how) {
  std::string error, lock_path;
  const fs::path path = dir.empty() ? fs::path(".") : fs::path(dir);
  if (mpi::rank(comm) == 0) {
    error = claim(path, dir, how);
    if (error.empty()) lock_path = (path / kOutputLockName).string();
  }
  OutputLock lock(lock_path);  // removed again if any rank fails below
  mpi::agree_on_failure<IoError>(comm, error);
  return lock;
}

// Writes `text` to `path` through a temporary file and a rename, so that a reader never sees
// a half-written file. Returns an error message, empty on success.
std::string write_file_atomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr) return fmt::format("cannot create {}: {}", tmp, std::strerror(errno));
  const bool written = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const int write_errno = errno;
  if (std::fclose(f) != 0 || !written) {
    const int e = written ? errno : write_errno;
    std::remove(tmp.c_str());
    return fmt::format("cannot write {}: {}", tmp, std::strerror(e));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    return fmt::format("cannot rename {} to {}: {}", tmp, path, ec.message());
  }
  return {};
}

}  // namespace dem2d
