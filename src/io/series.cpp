#include "io/series.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>  // fmt::join

#include <cerrno>
#include <cstring>
#include <iterator>
#include <type_traits>

#include "core/errors.hpp"

namespace dem2d {

namespace {
bool written(const SeriesColumn& column, bool iterative, bool ore) {
  return column.only == SeriesOnly::kAlways ||
         (iterative && column.only == SeriesOnly::kIterative) ||
         (ore && column.only == SeriesOnly::kOre);
}
}  // namespace

std::vector<std::string> series_columns(bool iterative, bool ore) {
  std::vector<std::string> columns;
  for (const SeriesColumn& column : kSeriesColumns) {
    if (written(column, iterative, ore)) columns.emplace_back(column.name);
  }
  return columns;
}

std::string series_columns_markdown() {
  std::string out = "| column | unit | meaning |\n| --- | --- | --- |\n";
  for (const SeriesColumn& c : kSeriesColumns) {
    out += fmt::format("| `{}` | {} | {} |\n", c.name, c.unit.empty() ? "–" : c.unit, c.doc);
  }
  return out;
}

SeriesWriter::SeriesWriter(const std::string& path, bool iterative, bool active, bool ore)
    : path_(path), iterative_(iterative), ore_(ore) {
  if (!active) return;
  file_.reset(std::fopen(path_.c_str(), "w"));
  if (!file_) throw IoError(fmt::format("cannot create {}: {}", path_, std::strerror(errno)));
  put(fmt::format("{}\n", fmt::join(series_columns(iterative_, ore_), ",")));
}

SeriesWriter::~SeriesWriter() = default;  // fclose flushes; its status cannot be reported

void SeriesWriter::write(const SeriesRow& r) {
  if (!file_) return;
  std::string line;
  const auto append = [&line](auto value) {
    if constexpr (std::is_same_v<decltype(value), double>) {
      // {:.17g}: 17 significant digits, enough for any double to read back bit for bit.
      fmt::format_to(std::back_inserter(line), "{:.17g}", value);
    } else {
      fmt::format_to(std::back_inserter(line), "{}", value);
    }
  };
  for (const SeriesColumn& column : kSeriesColumns) {
    if (!written(column, iterative_, ore_)) continue;
    if (!line.empty()) line += ',';
    std::visit([&](auto member) { append(r.*member); }, column.value);
  }
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
