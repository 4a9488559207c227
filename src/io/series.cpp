#include "io/series.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>  // fmt::join

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <type_traits>

#include "core/base/errors.hpp"
#include "io/output_dir.hpp"

namespace dem2d {

namespace {
bool written(const SeriesColumn& column, bool iterative, bool ore, bool drum) {
  return column.only == SeriesOnly::kAlways ||
         (iterative && column.only == SeriesOnly::kIterative) ||
         (ore && column.only == SeriesOnly::kOre) || (drum && column.only == SeriesOnly::kDrum);
}
}  // namespace

std::vector<std::string> series_columns(bool iterative, bool ore, bool drum) {
  std::vector<std::string> columns;
  for (const SeriesColumn& column : kSeriesColumns) {
    if (written(column, iterative, ore, drum)) columns.emplace_back(column.name);
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

std::FILE* continue_csv(const std::string& path, const std::string& header, std::size_t column,
                        double limit) {
  std::ifstream in(path);
  if (!in) {
    std::FILE* f = std::fopen(path.c_str(), "w");
    if (f == nullptr || std::fprintf(f, "%s\n", header.c_str()) < 0 || std::fflush(f) != 0)
      throw IoError(fmt::format("cannot create {}: {}", path, std::strerror(errno)));
    return f;
  }
  std::string line, kept;
  if (!std::getline(in, line) || line != header)
    throw IoError(
        fmt::format("cannot continue {}: its columns are not this run's ({})", path, header));
  kept = line + "\n";
  const auto fields = std::count(header.begin(), header.end(), ',');
  while (std::getline(in, line)) {
    // A row with fewer fields is a torn last row (a kill mid-write), whose first field may be
    // cut short too.
    if (std::count(line.begin(), line.end(), ',') != fields) break;
    std::size_t at = 0;  // where the column's value starts
    for (std::size_t c = 0; c < column && at < line.size(); ++c) {
      const std::size_t comma = line.find(',', at);
      at = comma == std::string::npos ? line.size() : comma + 1;
    }
    if (at >= line.size()) break;  // a torn last row (a kill mid-write)
    char* end = nullptr;
    const double value = std::strtod(line.c_str() + at, &end);
    if (end == line.c_str() + at || value > limit) break;
    kept += line + "\n";
  }
  const std::string temporary = path + ".tmp";
  std::FILE* out = std::fopen(temporary.c_str(), "w");
  if (out == nullptr || std::fwrite(kept.data(), 1, kept.size(), out) != kept.size() ||
      std::fclose(out) != 0 || std::rename(temporary.c_str(), path.c_str()) != 0)
    throw IoError(fmt::format("cannot write {}: {}", path, std::strerror(errno)));
  std::FILE* f = std::fopen(path.c_str(), "a");
  if (f == nullptr) throw IoError(fmt::format("cannot write {}: {}", path, std::strerror(errno)));
  return f;
}

SeriesWriter::SeriesWriter(const std::string& path, bool iterative, bool active, bool ore,
                           std::int64_t continue_after_step, bool drum)
    : path_(path), iterative_(iterative), ore_(ore), drum_(drum) {
  if (!active) return;
  const std::string header =
      fmt::format("{}", fmt::join(series_columns(iterative_, ore_, drum_), ","));
  if (continue_after_step >= 0) {
    file_.reset(continue_csv(path_, header, 1, static_cast<double>(continue_after_step)));
    return;
  }
  file_.reset(std::fopen(path_.c_str(), "w"));
  if (!file_) throw IoError(fmt::format("cannot create {}: {}", path_, std::strerror(errno)));
  put(header + "\n");
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
    if (!written(column, iterative_, ore_, drum_)) continue;
    if (!line.empty()) line += ',';
    std::visit([&](auto member) { append(r.*member); }, column.value);
  }
  line += '\n';
  put(line);
}

void SeriesWriter::put(const std::string& text) { append_to_log(file_.get(), path_, text); }

}  // namespace dem2d
