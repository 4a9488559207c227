#include "io/output_dir.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
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

// A process that has ended but not been reaped yet (state Z in /proc/PID/stat) still answers
// kill(pid, 0): it is not running.
bool is_zombie(long pid) {
  std::ifstream stat(fmt::format("/proc/{}/stat", pid));
  std::string line;
  if (!std::getline(stat, line)) return false;
  const std::size_t close = line.rfind(')');  // the name in parentheses may hold spaces
  return close != std::string::npos && close + 2 < line.size() && line[close + 2] == 'Z';
}

// The start time of process `pid` (field 22 of /proc/PID/stat, clock ticks since boot): with
// the pid, it names one process instance (a pid is reused, the pair is not). 0 when unknown.
std::uint64_t start_time(long pid) {
  std::ifstream stat(fmt::format("/proc/{}/stat", pid));
  std::string line;
  if (!std::getline(stat, line)) return 0;
  const std::size_t close = line.rfind(')');  // the name in parentheses may hold spaces
  if (close == std::string::npos) return 0;
  std::istringstream fields(line.substr(close + 1));
  std::string field;
  for (int k = 3; k <= 22 && fields >> field; ++k)
    if (k == 22) return std::strtoull(field.c_str(), nullptr, 10);
  return 0;
}

// Who wrote a lock file: "HOST PID START" (START 0: a lock without it).
struct LockHolder {
  std::string host;
  long pid = 0;
  std::uint64_t start = 0;
};

LockHolder read_holder(int fd) {
  std::string text(256, '\0');
  const ssize_t n = ::pread(fd, text.data(), text.size() - 1, 0);
  text.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
  LockHolder h;
  std::istringstream in(text);
  in >> h.host >> h.pid >> h.start;
  return h;
}

// Whether the holder's process runs on this host, for a file system without advisory locks:
// its pid alive, not a zombie, and started when the lock says (when the lock says).
bool running_here(const LockHolder& h, const std::string& host) {
  if (h.host != host || h.pid <= 0) return false;
  const std::uint64_t start = start_time(h.pid);
  return (::kill(static_cast<pid_t>(h.pid), 0) == 0 || errno == EPERM) && !is_zombie(h.pid) &&
         (h.start == 0 || start == h.start);
}

// The lock file, opened and locked (flock, held while the run lasts: the kernel releases it when
// the process ends, however it ends), or why not.
struct Locked {
  int fd = -1;
  bool created = false;  // no lock file was there
  bool live = false;     // held by a running dem2d: `holder` says which
  LockHolder holder;     // what the file said before
  std::string error;
};

// Opens the lock file and takes its advisory lock. A run that ends unlinks its lock file before
// it lets go of it, so a lock taken on a file no longer at `lock` is given back and taken again.
Locked acquire(const fs::path& lock, const std::string& host) {
  for (int attempt = 0; attempt < 8; ++attempt) {
    Locked l;
    l.fd = ::open(lock.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    l.created = l.fd >= 0;
    if (l.fd < 0 && errno == EEXIST) l.fd = ::open(lock.c_str(), O_RDWR | O_CLOEXEC);
    if (l.fd < 0 && errno == ENOENT) continue;  // removed in between
    if (l.fd < 0) {
      l.error = std::strerror(errno);
      return l;
    }
    l.holder = read_holder(l.fd);
    if (::flock(l.fd, LOCK_EX | LOCK_NB) != 0) {
      if (errno == EWOULDBLOCK)
        l.live = true;
      else
        l.live = running_here(l.holder, host);  // no advisory locks here
      if (l.live) return l;
    }
    struct stat held {
    }, named{};
    if (::fstat(l.fd, &held) == 0 && ::stat(lock.c_str(), &named) == 0 &&
        held.st_ino == named.st_ino && held.st_dev == named.st_dev)
      return l;
    ::close(l.fd);
  }
  Locked changing;
  changing.error = "its lock file keeps changing";
  return changing;
}

// Gives up a lock this claim took but does not keep: a lock file it created goes again, one that
// was there stays as it was.
void give_back(const Locked& l, const fs::path& lock) {
  if (l.created) ::unlink(lock.c_str());
  ::close(l.fd);
}

// Writes this run's "HOST PID START" into the lock file; false when it cannot.
bool write_holder(int fd, const std::string& host) {
  const std::string text = fmt::format("{} {} {}\n", host, ::getpid(), start_time(::getpid()));
  return ::ftruncate(fd, 0) == 0 &&
         ::pwrite(fd, text.data(), text.size(), 0) == static_cast<ssize_t>(text.size());
}

// Why a new run may not take a folder that holds output: what is there and what to do. A
// checkpoint there can be continued (--restart), which --overwrite would discard.
std::string refusal(const fs::path& dir, const std::string& shown,
                    const std::vector<std::string>& found) {
  std::error_code ec;
  if (!fs::exists(dir / kCheckpointFile, ec))
    return fmt::format(
        "output directory '{}' holds another run's output ({}); give this run a new folder with "
        "--output DIR, or --overwrite to replace that output",
        shown, fmt::join(found, ", "));
  return fmt::format(
      "output directory '{}' holds another run's output ({}), which can be continued: resume it "
      "with --restart {}, or give this run a new folder with --output DIR; --overwrite replaces "
      "that output and discards its checkpoint",
      shown, fmt::join(found, ", "), (dir / kCheckpointFile).string());
}

std::string in_use(const std::string& shown, const fs::path& lock, const LockHolder& h) {
  if (h.pid <= 0)
    return fmt::format(
        "output directory '{}' was claimed by another dem2d run starting at the same time (its "
        "lock file {} is held); give this run its own folder with --output DIR",
        shown, lock.string());
  return fmt::format(
      "output directory '{}' is in use by a dem2d run that is still running (pid {} on host {}, "
      "which holds the lock file {}); give this run its own folder with --output DIR",
      shown, h.pid, h.host, lock.string());
}

// The claim's verdict on rank 0: `error` empty when the folder is this run's now (its lock
// held by `fd`); `notice` when a dead run's lock was taken over.
struct Verdict {
  std::string error, notice;
  int fd = -1;
};

Verdict refused(std::string why) {
  Verdict v;
  v.error = std::move(why);
  return v;
}

Verdict claim(const fs::path& dir, const std::string& shown, Claim how) {
  if (const std::string reason = check_directory(dir); !reason.empty())
    return refused(
        fmt::format("cannot write to output directory '{}': {}; give a directory you can "
                    "write to",
                    shown, reason));
  const std::string host = this_host();
  const fs::path lock = dir / kOutputLockName;
  const Locked l = acquire(lock, host);
  if (!l.error.empty())
    return refused(fmt::format("cannot write to output directory '{}': {}", shown, l.error));
  if (l.live) {
    ::close(l.fd);
    return refused(in_use(shown, lock, l.holder));
  }
  std::vector<std::string> found;
  // A lock of another host's run: this host may not see that run's advisory lock.
  const bool elsewhere = !l.created && l.holder.pid > 0 && l.holder.host != host;
  if (elsewhere)
    found.push_back(
        fmt::format("{} of a run on host {} (pid {}), which may still be running: "
                    "this host cannot tell",
                    kOutputLockName, l.holder.host, l.holder.pid));
  std::error_code ec;
  for (const char* name : kRunOutputs)
    if (fs::exists(dir / name, ec)) found.emplace_back(name);
  if (!found.empty() && how == Claim::kNew) {
    give_back(l, lock);
    return refused(refusal(dir, shown, found));
  }
  if (how == Claim::kOverwrite)
    for (const char* name : kRunOutputs) fs::remove(dir / name, ec);
  if (!write_holder(l.fd, host)) {
    const int e = errno;
    give_back(l, lock);
    return refused(
        fmt::format("cannot write to output directory '{}': {}", shown, std::strerror(e)));
  }
  Verdict v;
  v.fd = l.fd;
  if (elsewhere)
    v.notice = fmt::format(
        "{}: note: took over the lock file of a dem2d run on host {} (pid {}), "
        "which this host cannot check\n",
        lock.string(), l.holder.host, l.holder.pid);
  else if (!l.created && l.holder.pid > 0)
    v.notice = fmt::format(
        "{}: note: took over the lock file of a dem2d run that did not end "
        "(pid {} on host {})\n",
        lock.string(), l.holder.pid, l.holder.host);
  return v;
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
  if (fd_ < 0) return;
  ::unlink(path_.c_str());  // before the lock goes: a run waiting for it sees a new file
  ::close(fd_);
}

OutputLock claim_output_directory(MPI_Comm comm, const std::string& dir, Claim how) {
  const fs::path path = dir.empty() ? fs::path(".") : fs::path(dir);
  Verdict v;
  if (mpi::rank(comm) == 0) v = claim(path, dir, how);
  OutputLock lock((path / kOutputLockName).string(), v.fd);  // released if any rank fails below
  mpi::agree_on_failure<IoError>(comm, v.error);
  if (!v.notice.empty()) {
    std::fputs(v.notice.c_str(), stderr);
    std::fflush(stderr);
  }
  return lock;
}

// Writes `text` to `path` through a temporary file and a rename, so that a reader never sees
// a half-written file. Returns an error message, empty on success.
void append_to_log(std::FILE* f, const std::string& path, std::string_view text) {
  errno = 0;
  if (std::fwrite(text.data(), 1, text.size(), f) != text.size() || std::fflush(f) != 0) {
    const int e = errno;
    std::clearerr(f);
    throw IoError(
        fmt::format("cannot write {}: {}", path, e != 0 ? std::strerror(e) : "write error"));
  }
}

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
