#include "io/deck_reader.hpp"

#include <algorithm>
#include <cmath>

#include "io/text.hpp"

namespace dem2d::deck {

std::string expected_text(Type type, const Bound& bound) {
  switch (type) {
    case Type::kNumber:
      return bound.unbounded() ? "a number" : "a number " + bound.text();
    case Type::kInteger:
      return "an integer " + bound.text();
    case Type::kVector:
      return "an array of two numbers [x, y]";
    case Type::kMaterialPair:
      return "two material names [\"a\", \"b\"]";
    case Type::kNumberList:
      return bound.unbounded() ? "an array of numbers" : "an array of numbers " + bound.text();
    default:
      return "a string";  // kString, kMaterial, kChoice
  }
}

void TableReader::invalid(std::string_view key, std::string_view what) const {
  const toml::node* node = find(key);
  if (node == nullptr) {
    // A rule between keys may name one the deck left out (a [feed] without a [drum] and
    // without material, or with neither period nor mass_rate): dereferencing the missing
    // value crashed (found by fuzzing, tests/fuzz/regressions). Said at the table instead.
    error(fmt::format("{}: {}", path_of(key), what));
    return;
  }
  diag_.error_at(*node, fmt::format("{} = {}: {}", path_of(key), diag_.shown(*node), what));
}

std::optional<double> TableReader::number(std::string_view key, const Bound& bound,
                                          Need need) const {
  const std::string expected = expected_text(Type::kNumber, bound);
  const toml::node* node = find(key);
  if (node == nullptr) {
    if (need == Need::kRequired) missing(key, expected);
    return std::nullopt;
  }
  std::optional<double> value;
  if (const auto* f = node->as_floating_point()) value = f->get();
  if (const auto* i = node->as_integer()) value = static_cast<double>(i->get());
  if (!value) {
    invalid(key, "expected " + expected);
  } else if (!std::isfinite(*value)) {
    invalid(key, "must be a finite number");
    value.reset();
  } else if (!bound.contains(*value)) {
    invalid(key, "must be " + bound.text());
    value.reset();
  }
  return value;
}

std::optional<std::int64_t> TableReader::integer(std::string_view key, const Bound& bound,
                                                 Need need, std::int64_t max) const {
  const std::string expected = expected_text(Type::kInteger, bound);
  const toml::node* node = find(key);
  if (node == nullptr) {
    if (need == Need::kRequired) missing(key, expected);
    return std::nullopt;
  }
  const auto* i = node->as_integer();
  if (i == nullptr) {
    invalid(key, "expected " + expected);
    return std::nullopt;
  }
  if (!bound.contains(static_cast<double>(i->get()))) {
    invalid(key, "must be " + bound.text());
    return std::nullopt;
  }
  if (i->get() > max) {
    invalid(key, fmt::format("must be <= {}", max));
    return std::nullopt;
  }
  return i->get();
}

std::optional<bool> TableReader::boolean(std::string_view key) const {
  const toml::node* node = find(key);
  if (node == nullptr) return std::nullopt;
  if (const auto* b = node->as_boolean()) return b->get();
  invalid(key, "expected true or false");
  return std::nullopt;
}

std::optional<std::string> TableReader::string(std::string_view key, Need need) const {
  const toml::node* node = find(key);
  if (node == nullptr) {
    if (need == Need::kRequired) missing(key, expected_text(Type::kString, {}));
    return std::nullopt;
  }
  if (const auto* s = node->as_string()) return s->get();
  invalid(key, "expected a string");
  return std::nullopt;
}

std::optional<Vec2> TableReader::pair(std::string_view key, Need need) const {
  const toml::node* node = find(key);
  if (node == nullptr) {
    if (need == Need::kRequired) missing(key, expected_text(Type::kVector, {}));
    return std::nullopt;
  }
  const auto* array = node->as_array();
  std::optional<double> xy[2];
  if (array != nullptr && array->size() == 2) {
    for (std::size_t i = 0; i < 2; ++i) {
      const toml::node& item = *array->get(i);
      if (const auto* f = item.as_floating_point()) xy[i] = f->get();
      if (const auto* n = item.as_integer()) xy[i] = static_cast<double>(n->get());
    }
  }
  if (!xy[0] || !xy[1]) {
    invalid(key, "expected an array of two numbers [x, y]");
    return std::nullopt;
  }
  if (!std::isfinite(*xy[0]) || !std::isfinite(*xy[1])) {
    invalid(key, "must be two finite numbers");
    return std::nullopt;
  }
  return Vec2{*xy[0], *xy[1]};
}

std::optional<std::vector<double>> TableReader::numbers(std::string_view key, const Bound& bound,
                                                        Need need) const {
  const std::string expected = expected_text(Type::kNumberList, bound);
  const toml::node* node = find(key);
  if (node == nullptr) {
    if (need == Need::kRequired) missing(key, expected);
    return std::nullopt;
  }
  const auto* array = node->as_array();
  if (array == nullptr || array->empty()) {
    invalid(key, "expected " + expected);
    return std::nullopt;
  }
  std::vector<double> values;
  for (std::size_t i = 0; i < array->size(); ++i) {
    const toml::node& item = *array->get(i);
    std::optional<double> v;
    if (const auto* f = item.as_floating_point()) v = f->get();
    if (const auto* n = item.as_integer()) v = static_cast<double>(n->get());
    if (!v || !std::isfinite(*v) || !bound.contains(*v)) {
      invalid(key, fmt::format("element {} = {}: expected {}", i, diag_.shown(item),
                               v ? "a finite number " + bound.text() : expected));
      return std::nullopt;
    }
    values.push_back(*v);
  }
  return values;
}

std::optional<std::string> TableReader::choice(std::string_view key,
                                               std::span<const std::string_view> names) const {
  const toml::node* node = find(key);
  if (node == nullptr) return std::nullopt;
  if (const auto* s = node->as_string()) {
    if (std::find(names.begin(), names.end(), s->get()) != names.end()) return s->get();
    std::string what = "must be one of " + quoted_list(names);
    if (const auto near = closest_match(s->get(), names)) {
      what += fmt::format("; did you mean {}?", quoted_string(*near));
    }
    invalid(key, what);
    return std::nullopt;
  }
  invalid(key, "expected a string, one of " + quoted_list(names));
  return std::nullopt;
}

std::optional<Value> TableReader::number_or_auto(std::string_view key, const Bound& bound,
                                                 std::string_view unit) const {
  const toml::node* node = find(key);
  if (node == nullptr) return std::nullopt;
  if (node->is_string() && node->as_string()->get() == "auto") return Value(std::string("auto"));
  if (!node->is_number()) {
    invalid(key, fmt::format("expected a number {} ({}) or \"auto\"", bound.text(), unit));
    return std::nullopt;
  }
  return as_value(number(key, bound));
}

const toml::table* TableReader::table(std::string_view key) const {
  const toml::node* node = find(key);
  if (node == nullptr) return nullptr;
  if (const auto* t = node->as_table()) return t;
  const std::string name = schema_.empty() ? std::string(key) : fmt::format("{}.{}", schema_, key);
  if (node->is_array_of_tables()) {
    error_at(key, fmt::format("{}: expected one table [{}], not an array of tables [[{}]]",
                              path_of(key), name, name));
  } else {
    invalid(key, fmt::format("expected a table [{}]", name));
  }
  return nullptr;
}

std::vector<const toml::table*> TableReader::table_array(std::string_view key) const {
  std::vector<const toml::table*> tables;
  const toml::node* node = find(key);
  if (node == nullptr) return tables;
  const std::string name = schema_.empty() ? std::string(key) : fmt::format("{}.{}", schema_, key);
  if (node->is_table()) {
    error_at(key, fmt::format("{}: expected an array of tables: write [[{}]], not [{}]",
                              path_of(key), name, name));
    return tables;
  }
  const auto* array = node->as_array();
  if (array == nullptr) {
    invalid(key, fmt::format("expected an array of tables [[{}]]", name));
    return tables;
  }
  for (std::size_t i = 0; i < array->size(); ++i) {
    const toml::node& item = *array->get(i);
    if (const auto* t = item.as_table()) {
      tables.push_back(t);
    } else {
      diag_.error_at(
          item, fmt::format("{}[{}] = {}: expected a table", path_of(key), i, diag_.shown(item)));
    }
  }
  return tables;
}

void TableReader::check_unknown_keys() const {
  for (const auto& [key, value] : table_) {
    const std::string_view name = key.str();
    if (std::find(valid_keys_.begin(), valid_keys_.end(), name) != valid_keys_.end()) continue;
    const auto near = closest_match(name, std::span<const std::string_view>(valid_keys_));
    const std::string prefix = schema_.empty() ? "" : schema_ + ".";
    std::string message;
    if (value.is_table() || value.is_array_of_tables()) {
      const char* open = value.is_table() ? "[" : "[[";
      const char* close = value.is_table() ? "]" : "]]";
      message = fmt::format("unknown table {}{}{}{}", open, prefix, name, close);
      if (near) message += fmt::format("; did you mean {}{}{}{}?", open, prefix, *near, close);
    } else {
      message = fmt::format("unknown key '{}' {}", name,
                            header_.empty() ? "at the top level" : "in " + header_);
      if (near) message += fmt::format("; did you mean '{}'?", *near);
    }
    if (!near) message += "; valid keys: " + comma_list(valid_keys_);
    diag_.error_at_key(key, value, message);
  }
}

}  // namespace dem2d::deck
