#include "io/particle_csv.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <optional>

#include "io/deck_schema.hpp"
#include "io/text.hpp"

namespace dem2d {
namespace {

enum Column { kX, kY, kRadius, kVx, kVy, kSpin, kMaterial, kColumns };  // as deck::kCsvColumns

// The field index of each column, -1 where the file has none.
using ColumnIndex = std::array<int, kColumns>;

// Collects the messages about one file, and stops keeping them after kMaxCsvErrors.
class CsvErrors {
 public:
  CsvErrors(const std::string& shown, std::string_view key, CsvPacking& packing)
      : shown_(shown),
        row_(key.empty() ? std::string() : fmt::format("{} row: ", key)),
        header_(key.empty() ? std::string() : fmt::format("{} header: ", key)),
        out_(packing.errors),
        file_(packing.file_errors) {}
  // About a data row, or about the header row.
  void at(int line, std::string_view message) { add(line, row_, message); }
  void header(int line, std::string_view message) { add(line, header_, message); }
  // About the file as a whole: the caller names the file and where the deck named it.
  void file(std::string message) {
    ++count_;
    file_.push_back(std::move(message));
  }
  void finish() {
    if (count_ > kMaxCsvErrors) {
      out_.push_back(fmt::format("{}: error: {} more errors in this file not shown", shown_,
                                 count_ - kMaxCsvErrors));
    }
  }
  int count() const { return count_; }

 private:
  void add(int line, const std::string& what, std::string_view message) {
    if (++count_ <= kMaxCsvErrors)
      out_.push_back(fmt::format("{}:{}: error: {}{}", shown_, line, what, message));
  }

  const std::string& shown_;
  std::string row_, header_;  // "fill[2].file row: ", "fill[2].file header: "; "" without a key
  std::vector<std::string>& out_;
  std::vector<std::string>& file_;
  int count_ = 0;
};

// One line split into its fields (RFC 4180): a field in double quotes may hold commas, and a
// doubled quote inside it stands for one quote; spaces around a field are dropped. A quoted
// field ends on its line (no value a packing holds spans lines).
struct Fields {
  std::vector<std::string> fields;
  std::string error;  // what is wrong with the line; "" when nothing
};

bool is_blank(char c) { return c == ' ' || c == '\t'; }

// The quoted field that starts at line[i] (a quote) into `field`; i is left after it. Returns
// false when the line ends inside it.
bool read_quoted(std::string_view line, std::size_t& i, std::string& field) {
  for (++i; i < line.size(); ++i) {
    if (line[i] != '"') {
      field += line[i];
    } else if (i + 1 < line.size() && line[i + 1] == '"') {
      field += '"';
      ++i;
    } else {
      ++i;
      return true;
    }
  }
  return false;
}

Fields split_fields(std::string_view line) {
  Fields out;
  for (std::size_t i = 0;; ++i) {  // ++i: past the comma
    while (i < line.size() && is_blank(line[i])) ++i;
    std::string field;
    if (i < line.size() && line[i] == '"') {
      const std::size_t number = out.fields.size() + 1;
      if (!read_quoted(line, i, field)) {
        out.error = fmt::format("field {} opens a quote that the line does not close", number);
        return out;
      }
      while (i < line.size() && is_blank(line[i])) ++i;
      if (i < line.size() && line[i] != ',') {
        out.error = fmt::format("field {} has text after its closing quote", number);
        return out;
      }
    } else {
      const std::size_t comma = std::min(line.find(',', i), line.size());
      field = std::string(trim(line.substr(i, comma - i)));
      i = comma;
    }
    out.fields.push_back(std::move(field));
    if (i >= line.size()) return out;
  }
}

// The header row: which field holds each column. Reports unknown, repeated and missing ones.
ColumnIndex read_header(const std::vector<std::string>& fields, int line, CsvErrors& errors) {
  ColumnIndex index;
  index.fill(-1);
  std::vector<std::string_view> suggested;  // a misspelt column is not also "missing"
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const std::string name = lowercase(fields[i]);
    const auto known = std::find(deck::kCsvColumns.begin(), deck::kCsvColumns.end(), name);
    if (known == deck::kCsvColumns.end()) {
      std::string message = fmt::format("unknown column '{}'", fields[i]);
      if (const auto near = closest_match(name, deck::kCsvColumns)) {
        message += fmt::format("; did you mean '{}'?", *near);
        suggested.push_back(*near);
      }
      errors.header(line, message + " (columns: " + comma_list(deck::kCsvColumns) + ")");
    } else if (int& slot = index[known - deck::kCsvColumns.begin()]; slot >= 0) {
      errors.header(line, fmt::format("column '{}' appears twice", name));
    } else {
      slot = static_cast<int>(i);
    }
  }
  for (const Column required : {kX, kY, kRadius}) {
    const std::string_view name = deck::kCsvColumns[required];
    if (index[required] < 0 &&
        std::find(suggested.begin(), suggested.end(), name) == suggested.end()) {
      errors.header(line, fmt::format("missing column '{}' (the header names x, y, radius and "
                                      "optionally vx, vy, spin, material)",
                                      name));
    }
  }
  return index;
}

// One data row as a particle, or nullopt after reporting what is wrong with it.
std::optional<ParticleSpec> read_row(const std::vector<std::string>& fields,
                                     const ColumnIndex& index, int line,
                                     const std::vector<std::string>& material_names,
                                     const CsvDefaults& defaults, CsvErrors& errors) {
  bool ok = true;
  const auto number = [&](Column column, double fallback) {
    if (index[column] < 0) return fallback;
    const std::string_view field = fields[static_cast<std::size_t>(index[column])];
    const std::string_view digits = field.starts_with('+') ? field.substr(1) : field;
    double value = 0.0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (digits.empty() || ec != std::errc() || end != digits.data() + digits.size() ||
        !std::isfinite(value)) {
      errors.at(line, fmt::format("column '{}' = {}: expected a number", deck::kCsvColumns[column],
                                  quoted_string(field)));
      ok = false;
    }
    return value;
  };
  ParticleSpec p;
  p.source_line = line;
  p.position = {number(kX, 0.0), number(kY, 0.0)};
  p.radius = number(kRadius, 0.0);
  p.velocity = {number(kVx, defaults.velocity.x), number(kVy, defaults.velocity.y)};
  p.spin = number(kSpin, 0.0);
  if (ok && !deck::kRadius.contains(p.radius)) {
    errors.at(line,
              fmt::format("column 'radius' = {}: must be {}", p.radius, deck::kRadius.text()));
    ok = false;
  }
  const std::string_view material =
      index[kMaterial] >= 0 ? std::string_view(fields[static_cast<std::size_t>(index[kMaterial])])
                            : std::string_view();
  p.material = material.empty() ? defaults.material : std::string(material);
  if (p.material.empty()) {
    errors.at(line, "no material: the material field is empty and the [[fill]] gives none");
    ok = false;
  } else if (!material.empty() && std::find(material_names.begin(), material_names.end(),
                                            p.material) == material_names.end()) {
    std::string message =
        fmt::format("column 'material' = {}: no such material", quoted_string(p.material));
    if (const auto near = closest_match(p.material, material_names)) {
      message += fmt::format("; did you mean {}?", quoted_string(*near));
    }
    errors.at(line, message + fmt::format(" (defined: {})", quoted_list(material_names)));
    ok = false;
  }
  if (!ok) return std::nullopt;
  return p;
}

}  // namespace

CsvPacking read_particle_csv(std::string_view text, const std::string& shown,
                             const std::vector<std::string>& material_names,
                             const CsvDefaults& defaults, std::string_view key) {
  CsvPacking packing;
  CsvErrors errors(shown, key, packing);
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);  // UTF-8 byte order mark
  std::optional<ColumnIndex> index;
  std::size_t n_fields = 0;
  for (int line = 1; !text.empty(); ++line) {
    const std::size_t newline = text.find('\n');
    const std::string_view row = trim(text.substr(0, newline));
    text.remove_prefix(newline == std::string_view::npos ? text.size() : newline + 1);
    if (row.empty() || row.front() == '#') continue;
    const Fields split = split_fields(row);
    const std::vector<std::string>& fields = split.fields;
    if (!split.error.empty() && !index) {
      errors.header(line, split.error);
      index.emplace().fill(-1);
      break;  // no columns: the rows cannot be read
    }
    if (!split.error.empty()) {
      errors.at(line, split.error);
      continue;
    }
    if (!index) {
      index = read_header(fields, line, errors);
      n_fields = fields.size();
      packing.has_material_column = (*index)[kMaterial] >= 0;
      const bool materials_known = packing.has_material_column || !defaults.material.empty();
      if (errors.count() > 0 || !materials_known) break;  // the rows cannot be read
      continue;
    }
    if (fields.size() != n_fields) {
      errors.at(line,
                fmt::format("{} fields, expected {} as in the header", fields.size(), n_fields));
      continue;
    }
    if (auto p = read_row(fields, *index, line, material_names, defaults, errors)) {
      packing.particles.push_back(std::move(*p));
    }
  }
  if (!index) {
    errors.file("is empty: expected a header row naming x, y, radius");
  } else if (packing.particles.empty() && errors.count() == 0 &&
             (packing.has_material_column || !defaults.material.empty())) {
    errors.file("has a header row but no rows: no particles");
  }
  errors.finish();
  if (errors.count() > 0) packing.particles.clear();
  return packing;
}

}  // namespace dem2d
