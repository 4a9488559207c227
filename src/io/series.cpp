#include "io/series.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>  // fmt::join

#include <cerrno>
#include <cstring>

#include "core/errors.hpp"

namespace dem2d {

std::vector<std::string> series_columns(bool iterative) {
  std::vector<std::string> columns{"time",
                                   "step",
                                   "particles",
                                   "contacts",
                                   "kinetic_energy",
                                   "rotational_energy",
                                   "potential_energy",
                                   "elastic_energy",
                                   "dissipated_energy",
                                   "drum_torque",
                                   "drum_power",
                                   "drive_work"};
  if (iterative) columns.emplace_back("passes");
  return columns;
}

SeriesWriter::SeriesWriter(const std::string& path, bool iterative, bool active)
    : path_(path), iterative_(iterative) {
  if (!active) return;
  file_.reset(std::fopen(path_.c_str(), "w"));
  if (!file_) throw IoError(fmt::format("cannot create {}: {}", path_, std::strerror(errno)));
  put(fmt::format("{}\n", fmt::join(series_columns(iterative_), ",")));
}

SeriesWriter::~SeriesWriter() = default;  // fclose flushes; its status cannot be reported

void SeriesWriter::write(const SeriesRow& r) {
  if (!file_) return;
  // {:.17g}: 17 significant digits, enough for any double to read back bit for bit.
  std::string line = fmt::format(
      "{:.17g},{},{},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}", r.time,
      r.step, r.particles, r.contacts, r.kinetic_energy, r.rotational_energy, r.potential_energy,
      r.elastic_energy, r.dissipated_energy, r.drum_torque, r.drum_power, r.drive_work);
  if (iterative_) line += fmt::format(",{:.17g}", r.passes);
  line += '\n';
  put(line);
}

void SeriesWriter::put(const std::string& text) {
  errno = 0;
  if (std::fwrite(text.data(), 1, text.size(), file_.get()) != text.size() ||
      std::fflush(file_.get()) != 0) {
    const int e = errno;
    std::clearerr(file_.get());
    throw IoError(
        fmt::format("cannot write {}: {}", path_, e != 0 ? std::strerror(e) : "write error"));
  }
}

}  // namespace dem2d
