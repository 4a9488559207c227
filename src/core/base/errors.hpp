// The errors dem2d reports to a user, each with its exit status (docs/architecture.md):
// 2 bad input or usage, 3 the run became unstable, 4 an I/O failure, 5 interrupted by SIGINT or
// SIGTERM after writing a checkpoint to resume from.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace dem2d {

enum ExitCode : int {
  kExitOk = 0,
  kExitInput = 2,
  kExitUnstable = 3,
  kExitIo = 4,
  kExitInterrupted = 5
};

// Bad input: one or more complete messages, each already formatted as
// "FILE:LINE:COL: error: ..." where a line is known.
class InputError : public std::runtime_error {
 public:
  explicit InputError(std::vector<std::string> messages)
      : std::runtime_error(join(messages)), messages_(std::move(messages)) {}
  explicit InputError(const std::string& message) : InputError(std::vector<std::string>{message}) {}
  const std::vector<std::string>& messages() const { return messages_; }

 private:
  static std::string join(const std::vector<std::string>& m) {
    std::string s;
    for (const auto& line : m) s += line + "\n";
    return s;
  }
  std::vector<std::string> messages_;
};

// A file could not be written or read (exit 4).
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace dem2d
