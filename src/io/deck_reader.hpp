// TableReader: the per-key checks of one table of the deck, shared by the deck parser
// (deck.cpp) and the placement checks (placement.cpp). Internal to the deck reader.
//
// It checks each key's type, range and presence, reports keys outside the table's vocabulary
// (deck_schema.hpp) with the closest valid one, and says every problem at the value's position
// through the Diagnostics, naming the key by its full dotted path (material[1].density).
#pragma once

#include <fmt/format.h>
#include <toml++/toml.h>

#include <climits>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/base/vec2.hpp"
#include "io/deck_diagnostics.hpp"
#include "io/deck_schema.hpp"

namespace dem2d::deck {

// What a key of `type` must hold, for messages: "a number > 0", "an array of two numbers [x, y]".
std::string expected_text(Type type, const Bound& bound);

template <class V>
std::optional<Value> as_value(std::optional<V> value) {
  if (!value) return std::nullopt;
  return Value(std::move(*value));
}

class TableReader {
 public:
  // Reads `table` as the described table `spec`; `index`: its element of an array of tables.
  // Messages name it by its dotted path ("material[1]", "" for the root) and, for unknown keys,
  // as a deck writes it ("[[material]]") or by its path without indices ("drum.lifter").
  template <class T>
  TableReader(Diagnostics& diag, const toml::table& table, const Table<T>& spec,
              std::optional<std::size_t> index = std::nullopt)
      : diag_(diag),
        table_(table),
        path_(index ? fmt::format("{}[{}]", spec.path, *index) : std::string(spec.path)),
        header_(spec.path.empty() ? std::string()
                : spec.repeated   ? fmt::format("[[{}]]", spec.path)
                                  : fmt::format("[{}]", spec.path)),
        schema_(spec.path),
        valid_keys_(key_names(spec.keys)) {}

  const std::string& path() const { return path_; }
  const toml::table& table() const { return table_; }
  int line() const { return static_cast<int>(table_.source().begin.line); }
  std::string path_of(std::string_view key) const {
    return path_.empty() ? std::string(key) : fmt::format("{}.{}", path_, key);
  }
  const toml::node* find(std::string_view key) const { return table_.get(key); }
  bool has(std::string_view key) const { return find(key) != nullptr; }

  // "material[1].density = -5: must be > 0", at the value's position.
  void invalid(std::string_view key, std::string_view what) const;
  // The value of `key` as the deck wrote it, for messages about another key.
  std::string shown(std::string_view key) const { return diag_.shown(*find(key)); }
  void error_at(std::string_view key, std::string_view message) const {
    diag_.error_at(*find(key), message);
  }
  // At the table itself (its header line).
  void error(std::string_view message) const { diag_.error_at(table_, message); }
  void missing(std::string_view key, std::string_view what) const {
    error(fmt::format("{} is required ({})", path_of(key), what));
  }

  std::optional<double> number(std::string_view key, const Bound& bound = kAnyNumber,
                               Need need = Need::kOptional) const;
  // An integer in `bound` and at most `max` (INT_MAX for the deck's int fields).
  std::optional<std::int64_t> integer(std::string_view key, const Bound& bound,
                                      Need need = Need::kOptional,
                                      std::int64_t max = INT_MAX) const;
  std::optional<bool> boolean(std::string_view key) const;
  std::optional<std::string> string(std::string_view key, Need need = Need::kOptional) const;
  // [x, y]: exactly two finite numbers (integers accepted).
  std::optional<Vec2> pair(std::string_view key, Need need = Need::kOptional) const;
  // [a, b, ...]: one or more finite numbers, each in `bound`.
  std::optional<std::vector<double>> numbers(std::string_view key, const Bound& bound,
                                             Need need = Need::kOptional) const;
  // One of a fixed set of words; a near miss gets a suggestion.
  std::optional<std::string> choice(std::string_view key,
                                    std::span<const std::string_view> names) const;
  // A number in `bound` or the word "auto" (run.dt); `unit` is named in the message.
  std::optional<Value> number_or_auto(std::string_view key, const Bound& bound,
                                      std::string_view unit) const;

  // A sub-table [name] (nullptr when absent or of another type, which is reported).
  const toml::table* table(std::string_view key) const;
  // The elements of an array of tables [[name]] (empty when absent or of another type).
  std::vector<const toml::table*> table_array(std::string_view key) const;

  // Every key that is not in this table's vocabulary, with the closest valid one.
  void check_unknown_keys() const;

 private:
  Diagnostics& diag_;
  const toml::table& table_;
  std::string path_;
  std::string header_;
  std::string schema_;
  std::vector<std::string_view> valid_keys_;
};

}  // namespace dem2d::deck
