#include "io/output_dir.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "core/errors.hpp"
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

}  // namespace

void prepare_output_directory(MPI_Comm comm, const std::string& dir) {
  std::string error;
  if (mpi::rank(comm) == 0) {
    const std::string reason = check_directory(dir.empty() ? fs::path(".") : fs::path(dir));
    if (!reason.empty())
      error = fmt::format("cannot write to output directory '{}': {}", dir, reason);
  }
  mpi::agree_on_failure<IoError>(comm, error);
}

}  // namespace dem2d
