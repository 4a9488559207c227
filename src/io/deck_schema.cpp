// The deck's description (deck_schema.hpp): the parts that are not tables, and the key tables
// of docs/input.md generated from it.
#include "io/deck_schema.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "io/text.hpp"

namespace dem2d::deck {

std::string Bound::text() const {
  if (hi == std::numeric_limits<double>::infinity()) {
    return fmt::format("{} {}", lo_open ? ">" : ">=", lo);
  }
  if (lo == -std::numeric_limits<double>::infinity()) {
    return fmt::format("{} {}", hi_open ? "<" : "<=", hi);
  }
  return fmt::format("in {}{}, {}{}", lo_open ? '(' : '[', lo, hi, hi_open ? ')' : ']');
}

std::string Bound::doc_text() const {
  if (unbounded()) return "–";
  if (hi == std::numeric_limits<double>::infinity()) {
    return fmt::format("{} {}", lo_open ? ">" : "≥", lo);
  }
  if (lo == -std::numeric_limits<double>::infinity()) {
    return fmt::format("{} {}", hi_open ? "<" : "≤", hi);
  }
  return fmt::format("{}{}, {}{}", lo_open ? '(' : '[', lo, hi, hi_open ? ')' : ']');
}

namespace {

std::string value_text(const Value& value, std::string (*number)(double)) {
  struct Visitor {
    std::string (*number)(double);
    std::string operator()(double v) const { return number(v); }
    std::string operator()(std::int64_t v) const { return fmt::format("{}", v); }
    std::string operator()(bool v) const { return v ? "true" : "false"; }
    std::string operator()(const std::string& v) const { return quoted_string(v); }
    std::string operator()(Vec2 v) const {
      return fmt::format("[{}, {}]", number(v.x), number(v.y));
    }
    std::string operator()(const Numbers& v) const {
      std::string out = "[";
      for (std::size_t i = 0; i < v.size(); ++i) out += (i > 0 ? ", " : "") + number(v[i]);
      return out + "]";
    }
    std::string operator()(const Names& v) const {
      std::string out = "[";
      for (std::size_t i = 0; i < v.size(); ++i) out += (i > 0 ? ", " : "") + quoted_string(v[i]);
      return out + "]";
    }
  };
  return std::visit(Visitor{number}, value);
}

}  // namespace

std::string toml_text(const Value& value) { return value_text(value, toml_number); }
std::string json_text(const Value& value) { return value_text(value, json_number); }

double degrees_for(double radians) {
  // Several doubles near radians / kRadiansPerDegree may convert back exactly; the one with
  // the shortest text is the one a person typed.
  const double guess = radians / kRadiansPerDegree;
  double best = guess;
  std::size_t best_length = std::numeric_limits<std::size_t>::max();
  double up = guess, down = guess;
  for (int i = 0; i <= 8; ++i) {
    for (const double candidate : {up, down}) {
      const std::size_t length = toml_number(candidate).size();
      if (candidate * kRadiansPerDegree == radians && length < best_length) {
        best = candidate;
        best_length = length;
      }
    }
    up = std::nextafter(up, std::numeric_limits<double>::infinity());
    down = std::nextafter(down, -std::numeric_limits<double>::infinity());
  }
  return best;
}

bool is_table_array(std::string_view path) {
  bool found = false;
  for_each_table([&](const auto& table) { found |= table.repeated && table.path == path; });
  return found;
}

std::string model_coefficients(ContactModelKind model) {
  std::vector<std::string_view> names;
  for (const auto& key : kMaterialKeys) {
    if (key.models != kAllModels && takes(key.models, model)) names.push_back(key.name);
  }
  return and_list(names);
}

// ---------------------------------------------------------------------------------------------
// The docs

namespace {

std::string_view type_text(Type type) {
  switch (type) {
    case Type::kNumber:
      return "float";
    case Type::kInteger:
      return "integer";
    case Type::kBool:
      return "bool";
    case Type::kString:
    case Type::kMaterial:
    case Type::kChoice:
      return "string";
    case Type::kVector:
      return "`[x, y]`";
    case Type::kNumberOrAuto:
      return "float or `\"auto\"`";
    case Type::kMaterialPair:
      return "`[\"a\", \"b\"]`";
    case Type::kNumberList:
      return "array of floats";
    case Type::kTable:
    case Type::kTableArray:
      break;
  }
  return "table";
}

// The "allowed" cell where the key does not spell it out: from the range or the choices.
template <class T>
std::string allowed_text(const Key<T>& key) {
  if (!key.allowed.empty()) return std::string(key.allowed);
  switch (key.type) {
    case Type::kNumber:
      return key.range.doc_text();
    case Type::kInteger:
      if (key.max != INT_MAX && key.max != std::numeric_limits<std::int64_t>::max()) {
        return Bound{key.range.lo, static_cast<double>(key.max), key.range.lo_open, false}
            .doc_text();
      }
      return key.range.doc_text();
    case Type::kNumberOrAuto:
      return key.range.doc_text() + " or `\"auto\"`";
    case Type::kChoice: {
      std::string out;
      for (const std::string_view word : key.choices) {
        out += fmt::format("{}`{}`", out.empty() ? "" : ", ", quoted_string(word));
      }
      return out;
    }
    case Type::kMaterial:
      return "a defined name";
    case Type::kMaterialPair:
      return "two defined names";
    case Type::kNumberList:
      return "each " + key.range.doc_text();
    default:
      return "–";
  }
}

// The "default" cell: required, the key's own words, or the Scene field's initial value.
template <class T>
std::string default_text(const Key<T>& key) {
  if (key.need == Need::kRequired) return "**required**";
  if (!key.default_text.empty()) return std::string(key.default_text);
  if (key.field.load == nullptr) return "–";
  const std::optional<Value> value = key.field.load(T{});
  return value ? fmt::format("`{}`", toml_text(*value)) : "–";
}

template <class T>
KeyTable key_table(const Table<T>& table) {
  KeyTable out{std::string(table.path), {}};
  for (const Key<T>& key : table.keys) {
    if (key.type == Type::kTable || key.type == Type::kTableArray) continue;  // own section
    out.rows.push_back({fmt::format("`{}`", key.name), std::string(type_text(key.type)),
                        default_text(key), key.unit.empty() ? "–" : std::string(key.unit),
                        allowed_text(key), std::string(key.doc)});
  }
  return out;
}

}  // namespace

std::vector<KeyTable> key_tables() {
  std::vector<KeyTable> tables;
  for_each_table([&](const auto& table) { tables.push_back(key_table(table)); });
  return tables;
}

std::string markdown_header() {
  return "| key | type | default | unit | allowed | meaning |\n"
         "| --- | --- | --- | --- | --- | --- |\n";
}

std::string markdown_row(const KeyRow& row) {
  std::string out = "|";
  for (const std::string* cell :
       {&row.key, &row.type, &row.default_value, &row.unit, &row.allowed, &row.meaning}) {
    out += cell->empty() ? " |" : " " + *cell + " |";
  }
  return out + "\n";
}

std::string markdown(const KeyTable& table) {
  std::string out = markdown_header();
  for (const KeyRow& row : table.rows) out += markdown_row(row);
  return out;
}

}  // namespace dem2d::deck
