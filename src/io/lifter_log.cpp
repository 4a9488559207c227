#include "io/lifter_log.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstring>
#include <iterator>

#include "core/base/errors.hpp"
#include "io/output_dir.hpp"
#include "io/series.hpp"

namespace dem2d {

LifterLog::LifterLog(const std::string& path, bool active, bool shell, double continue_after_time)
    : path_(path) {
  if (!active) return;
  const std::string header = std::string(kLiftersHeader) + (shell ? kLiftersShellColumns : "");
  if (continue_after_time >= 0.0) {
    file_.reset(continue_csv(path_, header, 0, continue_after_time));
    return;
  }
  file_.reset(std::fopen(path_.c_str(), "w"));
  if (!file_ || std::fprintf(file_.get(), "%s\n", header.c_str()) < 0 ||
      std::fflush(file_.get()) != 0)
    throw IoError(fmt::format("cannot create {}: {}", path_, std::strerror(errno)));
}

void LifterLog::write(double time, std::span<const LifterLoad> bars,
                      std::span<const ShellBar> shell) {
  if (!file_) return;
  std::string text;
  for (std::size_t b = 0; b < bars.size(); ++b) {
    const LifterLoad& l = bars[b];
    fmt::format_to(std::back_inserter(text), "{:.17g},{},{:.17g},{:.17g},{:.17g},{:.17g},{}", time,
                   b, l.angle_deg, l.normal, l.radial, l.torque, l.contacts);
    if (!shell.empty())
      fmt::format_to(std::back_inserter(text), ",{:.17g},{:.17g},{:.17g}", shell[b].tip_deflection,
                     shell[b].peak_von_mises, shell[b].root_stress);
    text += '\n';
  }
  append_to_log(file_.get(), path_, text);
}

}  // namespace dem2d
