// Deck reader: TOML text -> --set overrides -> validation -> Scene (docs/input.md).
//
// One toml::table goes through three stages. The overrides are applied to the tree, and every
// node they make is remembered with the option's text (Origins), so that a message about it
// names the option. Then a DeckParser reads every table in two passes. The per-key pass walks
// the table's description (deck_schema.hpp): a TableReader checks each key's type, range and
// presence and reports unknown keys with the closest valid one; each accepted value goes into
// the Scene through the key's field. The rules between keys of the table follow as code (one
// of speed / speed_rpm / critical_fraction, ...), then the checks across tables (material
// references, particle sources). Every message goes to one Diagnostics; nothing throws before
// all of that has run, except a TOML syntax error (no tree to check).
#include "io/deck.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <numbers>
#include <optional>
#include <span>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <utility>

#include "core/drum_geometry.hpp"
#include "core/errors.hpp"
#include "core/validate.hpp"
#include "io/deck_schema.hpp"
#include "io/particle_csv.hpp"
#include "io/text.hpp"

namespace dem2d {
namespace {

namespace fs = std::filesystem;
using deck::Bound;
using deck::Need;
using deck::Type;
using deck::Value;

// ---------------------------------------------------------------------------------------------
// Text helpers

// The whole of an open file into `text`; closes it. Returns 0, or the errno of a read error
// (EIO when the stream failed without one).
int read_and_close(std::FILE* stream, std::string& text) {
  char buffer[65536];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, stream)) > 0;)
    text.append(buffer, n);
  const bool failed = std::ferror(stream) != 0;
  const int read_errno = errno;
  std::fclose(stream);
  return failed ? (read_errno != 0 ? read_errno : EIO) : 0;
}

// A node as it would be written in TOML, for messages (shortest round-trip numbers).
std::string value_text(const toml::node& node) {
  if (const auto* s = node.as_string()) return quoted_string(s->get());
  if (const auto* i = node.as_integer()) return fmt::format("{}", i->get());
  if (const auto* f = node.as_floating_point()) return toml_number(f->get());
  if (const auto* b = node.as_boolean()) return b->get() ? "true" : "false";
  if (node.is_table()) return "{...}";
  if (const auto* a = node.as_array()) {
    constexpr std::size_t kShown = 6;
    std::string out = "[";
    for (std::size_t i = 0; i < a->size() && i < kShown; ++i) {
      if (i > 0) out += ", ";
      out += value_text(*a->get(i));
    }
    if (a->size() > kShown) out += ", ...";
    return out + "]";
  }
  std::ostringstream os;  // dates and times
  node.visit([&](const auto& v) { os << v; });
  return os.str();
}

// ---------------------------------------------------------------------------------------------
// Diagnostics: every message, each with its location

// The nodes that --set overrides made, with the option's text ("--set drum.speed=2").
using Origins = std::unordered_map<const toml::node*, std::string>;

class Diagnostics {
 public:
  Diagnostics(std::string file, const Origins& origins)
      : file_(std::move(file)), origins_(origins) {}

  void set_root(const toml::table* root) { root_ = root; }
  // The deck's text, so that messages show a value as the user wrote it ("2.0e11").
  void set_source(std::string_view text) {
    for (std::size_t start = 0; start <= text.size();) {
      const std::size_t end = std::min(text.find('\n', start), text.size());
      lines_.push_back(text.substr(start, end - start));
      start = end + 1;
    }
  }

  // A value as the deck wrote it when it is on one line there, else formatted.
  std::string shown(const toml::node& node) const {
    const toml::source_position& begin = node.source().begin;
    const toml::source_position& end = node.source().end;
    if (!origins_.contains(&node) && begin.line > 0 && begin.line == end.line &&
        begin.line <= lines_.size() && end.column > begin.column &&
        end.column - 1 <= lines_[begin.line - 1].size()) {
      return std::string(
          lines_[begin.line - 1].substr(begin.column - 1, end.column - begin.column));
    }
    return value_text(node);
  }

  // Where a value came from: the --set option that made it, else its deck position.
  std::string where(const toml::node& node) const { return location(node); }
  // At a value or table: the --set option that made it, else its deck position, else the file.
  void error_at(const toml::node& node, std::string_view message) { add(location(node), message); }
  // At a key: the key's own position when it is in the deck.
  void error_at_key(const toml::key& key, const toml::node& value, std::string_view message) {
    if (!origins_.contains(&value) && key.source().begin.line > 0) {
      add(position(key.source().begin), message);
    } else {
      add(location(value), message);
    }
  }
  void error(std::string_view message) { add(file_, message); }
  void error_in(std::string_view where, std::string_view message) { add(where, message); }
  void add(std::string complete_message) { messages_.push_back(std::move(complete_message)); }

  std::vector<std::string>& messages() { return messages_; }

 private:
  std::string position(const toml::source_position& at) const {
    return fmt::format("{}:{}:{}", file_, at.line, at.column);
  }
  std::string location(const toml::node& node) const {
    if (const auto it = origins_.find(&node); it != origins_.end()) return it->second;
    if (&node == root_ || node.source().begin.line == 0) return file_;
    return position(node.source().begin);
  }
  void add(std::string_view where, std::string_view message) {
    messages_.push_back(fmt::format("{}: error: {}", where, message));
  }

  std::string file_;
  const Origins& origins_;
  const toml::table* root_ = nullptr;
  std::vector<std::string> messages_;
  std::vector<std::string_view> lines_;
};

// What a key of `type` must hold, for messages: "a number > 0", "an array of two numbers [x, y]".
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
    default:
      return "a string";  // kString, kMaterial, kChoice
  }
}

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
  TableReader(Diagnostics& diag, const toml::table& table, const deck::Table<T>& spec,
              std::optional<std::size_t> index = std::nullopt)
      : diag_(diag),
        table_(table),
        path_(index ? fmt::format("{}[{}]", spec.path, *index) : std::string(spec.path)),
        header_(spec.path.empty() ? std::string()
                : spec.repeated   ? fmt::format("[[{}]]", spec.path)
                                  : fmt::format("[{}]", spec.path)),
        schema_(spec.path),
        valid_keys_(deck::key_names(spec.keys)) {}

  const std::string& path() const { return path_; }
  const toml::table& table() const { return table_; }
  int line() const { return static_cast<int>(table_.source().begin.line); }
  std::string path_of(std::string_view key) const {
    return path_.empty() ? std::string(key) : fmt::format("{}.{}", path_, key);
  }
  const toml::node* find(std::string_view key) const { return table_.get(key); }
  bool has(std::string_view key) const { return find(key) != nullptr; }

  // "material[1].density = -5: must be > 0", at the value's position.
  void invalid(std::string_view key, std::string_view what) const {
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

  std::optional<double> number(std::string_view key, const Bound& bound = deck::kAnyNumber,
                               Need need = Need::kOptional) const {
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

  // An integer in `bound` and at most `max` (INT_MAX for the deck's int fields).
  std::optional<std::int64_t> integer(std::string_view key, const Bound& bound,
                                      Need need = Need::kOptional,
                                      std::int64_t max = INT_MAX) const {
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

  std::optional<bool> boolean(std::string_view key) const {
    const toml::node* node = find(key);
    if (node == nullptr) return std::nullopt;
    if (const auto* b = node->as_boolean()) return b->get();
    invalid(key, "expected true or false");
    return std::nullopt;
  }

  std::optional<std::string> string(std::string_view key, Need need = Need::kOptional) const {
    const toml::node* node = find(key);
    if (node == nullptr) {
      if (need == Need::kRequired) missing(key, expected_text(Type::kString, {}));
      return std::nullopt;
    }
    if (const auto* s = node->as_string()) return s->get();
    invalid(key, "expected a string");
    return std::nullopt;
  }

  // [x, y]: exactly two finite numbers (integers accepted).
  std::optional<Vec2> pair(std::string_view key, Need need = Need::kOptional) const {
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

  // One of a fixed set of words; a near miss gets a suggestion.
  std::optional<std::string> choice(std::string_view key,
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

  // A number in `bound` or the word "auto" (run.dt); `unit` is named in the message.
  std::optional<Value> number_or_auto(std::string_view key, const Bound& bound,
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

  // A sub-table [name] (nullptr when absent or of another type, which is reported).
  const toml::table* table(std::string_view key) const {
    const toml::node* node = find(key);
    if (node == nullptr) return nullptr;
    if (const auto* t = node->as_table()) return t;
    const std::string name =
        schema_.empty() ? std::string(key) : fmt::format("{}.{}", schema_, key);
    if (node->is_array_of_tables()) {
      error_at(key, fmt::format("{}: expected one table [{}], not an array of tables [[{}]]",
                                path_of(key), name, name));
    } else {
      invalid(key, fmt::format("expected a table [{}]", name));
    }
    return nullptr;
  }

  // The elements of an array of tables [[name]] (empty when absent or of another type).
  std::vector<const toml::table*> table_array(std::string_view key) const {
    std::vector<const toml::table*> tables;
    const toml::node* node = find(key);
    if (node == nullptr) return tables;
    const std::string name =
        schema_.empty() ? std::string(key) : fmt::format("{}.{}", schema_, key);
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

  // Every key that is not in this table's vocabulary, with the closest valid one.
  void check_unknown_keys() const {
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

 private:
  Diagnostics& diag_;
  const toml::table& table_;
  std::string path_;
  std::string header_;
  std::string schema_;
  std::vector<std::string_view> valid_keys_;
};

// ---------------------------------------------------------------------------------------------
// Overrides: --set KEY=VALUE applied to the tree

void record_origin(const toml::node& node, const std::string& where, Origins& origins) {
  origins[&node] = where;
  if (const auto* t = node.as_table()) {
    for (const auto& [key, value] : *t) record_origin(value, where, origins);
  } else if (const auto* a = node.as_array()) {
    for (const auto& item : *a) record_origin(item, where, origins);
  }
}

void forget_origin(const toml::node& node, Origins& origins) {
  origins.erase(&node);
  if (const auto* t = node.as_table()) {
    for (const auto& [key, value] : *t) forget_origin(value, origins);
  } else if (const auto* a = node.as_array()) {
    for (const auto& item : *a) forget_origin(item, origins);
  }
}

bool is_index(std::string_view s) {
  return !s.empty() && s.size() < 10 &&
         std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// True when `s` is well-formed UTF-8 (no overlong forms, surrogates or code points beyond
// U+10FFFF), as TOML requires of a deck.
bool valid_utf8(std::string_view s) {
  static constexpr std::uint32_t kSmallest[] = {0, 0x80, 0x800, 0x10000};  // by extra bytes
  for (std::size_t i = 0; i < s.size();) {
    const auto lead = static_cast<unsigned char>(s[i]);
    const int extra = lead < 0x80 ? 0 : lead >= 0xF0 ? 3 : lead >= 0xE0 ? 2 : lead >= 0xC0 ? 1 : -1;
    if (extra < 0 || lead > 0xF4 || s.size() - i <= static_cast<std::size_t>(extra)) return false;
    std::uint32_t code = extra == 0 ? lead : lead & (0x3Fu >> extra);
    for (int k = 1; k <= extra; ++k) {
      const auto next = static_cast<unsigned char>(s[i + static_cast<std::size_t>(k)]);
      if ((next & 0xC0) != 0x80) return false;
      code = (code << 6) | (next & 0x3Fu);
    }
    if (code < kSmallest[extra] || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF))
      return false;
    i += static_cast<std::size_t>(extra) + 1;
  }
  return true;
}

// Sets table[key] to VALUE read as one TOML value ("1.5", "[0, -9.81]", "true", "'steel'"),
// or, when VALUE is not one, as a bare string ("auto", "steel").
void assign_override_value(toml::table& table, const std::string& key, std::string_view value) {
  try {
    toml::table holder = toml::parse(std::string("v = ") + std::string(value));
    if (holder.size() == 1) {
      if (toml::node* parsed = holder.get("v")) {
        parsed->visit([&](auto& v) { table.insert_or_assign(key, std::move(v)); });
        return;
      }
    }
  } catch (const toml::parse_error&) {
    // Not a TOML value: a bare string.
  }
  table.insert_or_assign(key, std::string(value));
}

// The element of an array of tables named by `selector`: an index, or a [[material]] name.
toml::table* select_element(toml::array& array, std::string_view selector) {
  if (is_index(selector)) {
    const std::size_t index = std::stoul(std::string(selector));
    return index < array.size() ? array.get(index)->as_table() : nullptr;
  }
  for (auto& item : array) {
    auto* t = item.as_table();
    if (t == nullptr) continue;
    if (const auto* name = t->get_as<std::string>("name"); name && name->get() == selector) {
      return t;
    }
  }
  return nullptr;
}

std::string element_choices(const toml::array& array) {
  std::vector<std::string> names;
  for (const auto& item : array) {
    if (const auto* t = item.as_table()) {
      if (const auto* name = t->get_as<std::string>("name")) names.push_back(name->get());
    }
  }
  std::string text =
      array.empty() ? "there are none" : fmt::format("an index 0 to {}", array.size() - 1);
  if (!names.empty()) text += " or a name: " + quoted_list(names);
  return text;
}

// A --set of one key of an alternative group (deck_schema.hpp) removes the deck's value of the
// others in the same table. One set by another --set stays, and the rules between keys refuse
// the pair.
void drop_alternatives(toml::table& table, std::string_view schema, std::string_view key,
                       const Origins& origins) {
  for (const deck::AlternativeKeys& group : deck::kAlternativeKeys) {
    if (group.table != schema ||
        std::find(group.keys.begin(), group.keys.end(), key) == group.keys.end())
      continue;
    for (const std::string_view other : group.keys) {
      if (other.empty() || other == key) continue;
      const toml::node* node = table.get(other);
      if (node != nullptr && !origins.contains(node)) table.erase(other);
    }
  }
}

// Applies one override; a problem with the option itself (not with the value it sets, which
// the validation reports) is an error naming the option.
void apply_override(toml::table& root, const std::string& option, Origins& origins,
                    Diagnostics& diag) {
  const std::string where = "--set " + option;
  const auto fail = [&](std::string_view message) { diag.error_in(where, message); };
  // A value taken as a bare string let bytes that are not UTF-8 into the scene, and then its
  // resolved deck (run.json) did not read back (found with the fuzz target).
  if (!valid_utf8(option)) {
    fail("not valid UTF-8 text (a deck and its values are UTF-8)");
    return;
  }
  const std::size_t equals = option.find('=');
  if (equals == std::string::npos) {
    fail("expected KEY=VALUE, e.g. drum.speed=1.5");
    return;
  }
  const std::string_view key_text = trim(std::string_view(option).substr(0, equals));
  const std::string_view value = trim(std::string_view(option).substr(equals + 1));
  std::vector<std::string> segments;
  for (std::size_t start = 0;;) {
    const std::size_t dot = key_text.find('.', start);
    segments.emplace_back(trim(key_text.substr(start, dot - start)));
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }
  if (std::any_of(segments.begin(), segments.end(), [](const auto& s) { return s.empty(); })) {
    fail(fmt::format("'{}' is not a dotted key path such as drum.speed", key_text));
    return;
  }

  toml::table* table = &root;
  std::string schema;  // the path without element selectors: "drum.lifter"
  std::string shown;   // the path as messages write it: "drum.lifter[0]"
  for (std::size_t i = 0; i + 1 < segments.size(); ++i) {
    const std::string& segment = segments[i];
    schema = schema.empty() ? segment : schema + "." + segment;
    shown = shown.empty() ? segment : shown + "." + segment;
    toml::node* node = table->get(segment);
    if (deck::is_table_array(schema)) {
      toml::array* array = node != nullptr ? node->as_array() : nullptr;
      if (array == nullptr) {
        fail(fmt::format("the deck has no [[{}]] table", schema));
        return;
      }
      if (i + 2 >= segments.size()) {
        fail(fmt::format("name a key of one [[{}]] element: {}.INDEX.KEY", schema, schema));
        return;
      }
      const std::string& selector = segments[++i];
      table = select_element(*array, selector);
      if (table == nullptr) {
        fail(fmt::format("no [[{}]] element '{}'; give {}", schema, selector,
                         element_choices(*array)));
        return;
      }
      shown += is_index(selector) ? fmt::format("[{}]", selector) : "." + selector;
      continue;
    }
    if (node == nullptr) {
      node = table->insert(segment, toml::table{}).first->second.as_table();
      record_origin(*node, where, origins);
    }
    table = node->as_table();
    if (table == nullptr) {
      fail(fmt::format("{} is a value, not a table", shown));
      return;
    }
  }
  const std::string& last = segments.back();
  const std::string last_schema = schema.empty() ? last : schema + "." + last;
  if (deck::is_table_array(last_schema)) {
    fail(fmt::format("cannot set all of [[{}]]; set one key of one element: {}.INDEX.KEY",
                     last_schema, last_schema));
    return;
  }
  if (const toml::node* old = table->get(last)) forget_origin(*old, origins);
  drop_alternatives(*table, schema, last, origins);
  assign_override_value(*table, last, value);
  record_origin(*table->get(last), where, origins);
}

// ---------------------------------------------------------------------------------------------
// DeckParser: the tree -> a Scene, every table and every cross-reference checked

// The values that the per-key pass accepted in one table, by key, for the rules between keys.
class Accepted {
 public:
  void add(std::string_view key, Value value) { values_.emplace_back(key, std::move(value)); }
  bool has(std::string_view key) const { return find(key) != nullptr; }
  template <class V>
  std::optional<V> get(std::string_view key) const {
    const Value* value = find(key);
    if (value == nullptr || !std::holds_alternative<V>(*value)) return std::nullopt;
    return std::get<V>(*value);
  }

 private:
  const Value* find(std::string_view key) const {
    for (const auto& [name, value] : values_) {
      if (name == key) return &value;
    }
    return nullptr;
  }
  std::vector<std::pair<std::string_view, Value>> values_;
};

// A key that the keys around it make required (a fill's material, unless it reads a file).
template <class T>
void require(const TableReader& r, const deck::Table<T>& spec, std::string_view name) {
  if (r.has(name)) return;
  const deck::Key<T>* key = deck::find_key(spec.keys, name);
  r.missing(name, expected_text(key->type, key->range));
}

// ---------------------------------------------------------------------------------------------
// Placement: where the deck's own particles start (docs/input.md, "Placement")

// The particles that one [[fill]] file added to Scene::particles, and the file as messages
// name it.
struct FileRows {
  std::size_t first = 0;
  std::size_t count = 0;
  std::size_t fill = 0;  // the element of [[fill]]
  std::string shown;
  int reported = 0;  // messages about its rows so far
};

// Checks the particles the deck places itself, the [[particle]] tables and then the rows of the
// [[fill]] files (as Scene::particles holds them), before step 1: inside the drum, clear of the
// lifter bars, and apart from each other, each up to the one tolerance kPlacementOverlap. A
// particle that overlaps the drum's shell (circle or polygon) or a lifter bar by more than
// kPlacementOverlap of its radius, or another particle by more than kPlacementOverlap of the
// smaller radius, is bad input at its table's position, or at its CSV row (at most
// kMaxCsvErrors rows of a file, then a count of the others).
class Placement {
 public:
  // The overlap a particle may start with, as a fraction of its radius (of the smaller one for
  // a pair): the same for pairs, the shell and the lifter bars, so that a packing saved from a
  // settled run, by dem2d or another code, passes whole (a resting Hertz contact overlaps well
  // under 1 %: 200 steel balls of 8 mm settled by dem2d rest on the shell with at most 0.01 %).
  // The first step pushes such a contact apart like any other.
  static constexpr double kPlacementOverlap = 0.05;

  Placement(const Scene& scene, Diagnostics& diag, const std::vector<const toml::table*>& tables,
            std::vector<FileRows> files)
      : scene_(scene), drum_(scene.drum), diag_(diag), tables_(tables), files_(std::move(files)) {}

  void check() {
    for (std::size_t i = 0; i < scene_.particles.size(); ++i) {
      if (in_drum(i)) clear_of_lifters(i);
    }
    check_pairs();
    for (const FileRows& file : files_) {
      if (file.reported > kMaxCsvErrors) {
        diag_.add(fmt::format("{}: error: {} more misplaced rows in this file not shown",
                              file.shown, file.reported - kMaxCsvErrors));
      }
    }
  }

 private:
  // Inside the drum's circle or polygon, by the particle's clearance from the nearest side: an
  // overlap with the shell (radius - clearance) of at most kPlacementOverlap of the radius.
  bool in_drum(std::size_t i) {
    const DrumSpec& d = scene_.drum;
    const ParticleSpec& p = scene_.particles[i];
    if (!d.present) return false;
    const double clearance = drum_.shell_clearance(p.position);
    const double overlap = p.radius - clearance;
    if (overlap <= kPlacementOverlap * p.radius) return true;
    const std::string drum =
        fmt::format("the drum (radius {:g} m about [{:g}, {:g}]{})", d.radius, d.center.x,
                    d.center.y, d.sides >= 3 ? fmt::format(", {} sides", d.sides) : std::string());
    report(i, clearance <= -p.radius
                  ? fmt::format("the particle (radius {:g} m) lies outside {}; place it at least "
                                "its radius inside the shell",
                                p.radius, drum)
                  : fmt::format("the particle (radius {:g} m) overlaps the shell of {} by {:.3g} "
                                "% of its radius; {}",
                                p.radius, drum, 100.0 * overlap / p.radius, allowed()));
    return false;
  }

  // Clear of the bars: nearer to none than its radius less kPlacementOverlap of it.
  void clear_of_lifters(std::size_t i) {
    const ParticleSpec& p = scene_.particles[i];
    const double reach = p.radius - kPlacementOverlap * p.radius;
    const auto bar = drum_.bar_overlap(p.position, reach);
    if (!bar) return;
    const std::string which = fmt::format(
        "bar {} of drum.lifter[{}] (the bars at the drum's initial angle)", bar->bar, bar->lifter);
    report(i, bar->inside
                  ? fmt::format("the particle (radius {:g} m) lies inside {}; place it clear of "
                                "the lifters",
                                p.radius, which)
                  : fmt::format("the particle (radius {:g} m) overlaps {} by {:.3g} % of its "
                                "radius; {}",
                                p.radius, which, 100.0 * (p.radius - bar->distance) / p.radius,
                                allowed()));
  }

  // The tolerance, as every overlap message states it.
  static std::string allowed() {
    return fmt::format("at most {:g} % is allowed at the start", 100.0 * kPlacementOverlap);
  }

  // Pairs closer than allowed, found on a grid of cells as wide as the largest diameter, and
  // reported at the later particle in deck order.
  void check_pairs() {
    const std::vector<ParticleSpec>& ps = scene_.particles;
    double r_max = 0.0;
    for (const ParticleSpec& p : ps) r_max = std::max(r_max, p.radius);
    const double h = 2.0 * r_max;
    const auto cell = [h](double x) {  // clamped: a far-away particle is reported anyway
      return static_cast<std::int64_t>(std::clamp(std::floor(x / h), -1.0e9, 1.0e9));
    };
    const auto key = [](std::int64_t cx, std::int64_t cy) {
      return (cx << 32) ^ (cy & 0xffffffff);
    };
    std::unordered_map<std::int64_t, std::vector<std::size_t>> cells;
    for (std::size_t i = 0; i < ps.size(); ++i)
      cells[key(cell(ps[i].position.x), cell(ps[i].position.y))].push_back(i);
    std::vector<std::pair<std::size_t, std::size_t>> close;  // (later, earlier)
    for (std::size_t i = 0; i < ps.size(); ++i) {
      const std::int64_t cx = cell(ps[i].position.x), cy = cell(ps[i].position.y);
      for (std::int64_t dx = -1; dx <= 1; ++dx)
        for (std::int64_t dy = -1; dy <= 1; ++dy) {
          const auto it = cells.find(key(cx + dx, cy + dy));
          if (it == cells.end()) continue;
          for (const std::size_t j : it->second)
            if (j > i && overlap(i, j) > kPlacementOverlap * smaller(i, j))
              close.emplace_back(j, i);
        }
    }
    std::sort(close.begin(), close.end());
    for (const auto& [j, i] : close) report_pair(i, j);
  }

  double overlap(std::size_t i, std::size_t j) const {
    const ParticleSpec& p = scene_.particles[i];
    const ParticleSpec& q = scene_.particles[j];
    return p.radius + q.radius - norm(q.position - p.position);
  }
  double smaller(std::size_t i, std::size_t j) const {
    return std::min(scene_.particles[i].radius, scene_.particles[j].radius);
  }

  void report_pair(std::size_t i, std::size_t j) {
    const double gap = norm(scene_.particles[j].position - scene_.particles[i].position);
    const double s = smaller(i, j);
    report(j, gap <= 1e-9 * s
                  ? fmt::format("coincides with {}; give each particle its own place", name(i))
                  : fmt::format("overlaps {} by {:.3g} % of the smaller radius; {}", name(i),
                                100.0 * overlap(i, j) / s, allowed()));
  }

  // The file whose rows hold particle i (i past the tables).
  FileRows& file_of(std::size_t i) {
    auto it = std::upper_bound(files_.begin(), files_.end(), i,
                               [](std::size_t k, const FileRows& f) { return k < f.first; });
    return *(it - 1);
  }

  // "particle[3] (line 12)", or a row "packing.csv:4".
  std::string name(std::size_t i) {
    if (i < tables_.size())
      return fmt::format("particle[{}] (line {})", i, scene_.particles[i].source_line);
    return fmt::format("{}:{}", file_of(i).shown, scene_.particles[i].source_line);
  }

  // At a table's position, or at the CSV row ("fill[2].file row: position = [x, y]: ...").
  void report(std::size_t i, std::string_view what) {
    if (i < tables_.size()) {
      TableReader(diag_, *tables_[i], deck::kParticle, i).invalid("position", what);
      return;
    }
    FileRows& file = file_of(i);
    if (++file.reported > kMaxCsvErrors) return;
    const ParticleSpec& p = scene_.particles[i];
    diag_.add(fmt::format("{}:{}: error: fill[{}].file row: position = [{:g}, {:g}]: {}",
                          file.shown, p.source_line, file.fill, p.position.x, p.position.y, what));
  }

  const Scene& scene_;
  DrumGeometry drum_;
  Diagnostics& diag_;
  const std::vector<const toml::table*>& tables_;
  std::vector<FileRows> files_;
};

class DeckParser {
 public:
  DeckParser(const toml::table& root, Diagnostics& diag, fs::path deck_dir)
      : root_(root), diag_(diag), deck_dir_(std::move(deck_dir)) {}

  Scene parse() {
    const TableReader root(diag_, root_, deck::kTopLevel);
    read_keys(root, deck::kTopLevel, scene_);  // the title; the tables below
    if (const auto* t = root.table("run")) read_run(*t);
    if (const auto* t = root.table("contact")) read_contact(*t);
    const auto materials = root.table_array("material");
    for (std::size_t i = 0; i < materials.size(); ++i) read_material(*materials[i], i);
    const auto interactions = root.table_array("interaction");
    for (std::size_t i = 0; i < interactions.size(); ++i) read_interaction(*interactions[i], i);
    const auto* drum = root.table("drum");
    if (drum != nullptr) read_drum(*drum);
    // [[particle]] before [[fill]]: file fills append their particles after the explicit ones.
    const auto particles = root.table_array("particle");
    for (std::size_t i = 0; i < particles.size(); ++i) read_particle(*particles[i], i);
    const auto fills = root.table_array("fill");
    for (std::size_t i = 0; i < fills.size(); ++i) read_fill(*fills[i], i);
    if (diag_.messages().empty()) Placement(scene_, diag_, particles, file_rows_).check();
    const auto walls = root.table_array("wall");
    for (std::size_t i = 0; i < walls.size(); ++i) read_wall(*walls[i], i);
    if (const auto* t = root.table("breakage")) read_breakage(*t);
    if (const auto* t = root.table("feed")) read_feed(*t);
    if (const auto* t = root.table("sieve")) read_sieve(*t);
    if (const auto* t = root.table("output")) read_output(*t);

    if (materials.empty() &&
        (drum != nullptr || !fills.empty() || !particles.empty() || !walls.empty())) {
      diag_.error(
          "no [[material]] is defined; every [[fill]], [[particle]], [[wall]] and the [drum] "
          "name one");
    }
    if (fills.empty() && particles.empty()) {
      diag_.error("no particles: add a [[fill]] or a [[particle]] table");
    }
    return std::move(scene_);
  }

 private:
  // The per-key pass over one table: unknown keys, then each described key's presence, type,
  // range and contact model. An accepted value goes into `target` through the key's field and
  // is returned for the rules between keys, which the caller checks next. (A value that breaks
  // such a rule may already be stored: the error discards the whole Scene.)
  template <class T>
  Accepted read_keys(const TableReader& r, const deck::Table<T>& spec, T& target) {
    r.check_unknown_keys();
    Accepted accepted;
    for (const deck::Key<T>& key : spec.keys) {
      if (model_ && r.has(key.name) && !deck::takes(key.models, *model_)) {
        // Another model's coefficient is an error rather than silently unused.
        r.invalid(key.name, fmt::format("not used by contact.model = \"{}\", which takes {}",
                                        deck::choice_name(deck::kContactModels, *model_),
                                        deck::model_coefficients(*model_)));
        continue;
      }
      std::optional<Value> value = read_value(r, key);
      if (!value) continue;
      if (key.field.store != nullptr) key.field.store(target, *value);
      accepted.add(key.name, std::move(*value));
    }
    return accepted;
  }

  // One key checked by its type: the value, or nullopt when absent or invalid (reported).
  template <class T>
  std::optional<Value> read_value(const TableReader& r, const deck::Key<T>& key) {
    switch (key.type) {
      case Type::kNumber:
        return as_value(r.number(key.name, key.range, key.need));
      case Type::kInteger:
        return as_value(r.integer(key.name, key.range, key.need, key.max));
      case Type::kBool:
        return as_value(r.boolean(key.name));
      case Type::kString:
        return as_value(r.string(key.name, key.need));
      case Type::kMaterial:
        return as_value(material_ref(r, key.name, key.need));
      case Type::kChoice:
        return as_value(r.choice(key.name, key.choices));
      case Type::kVector:
        return as_value(r.pair(key.name, key.need));
      case Type::kNumberOrAuto:
        return r.number_or_auto(key.name, key.range, key.unit);
      case Type::kMaterialPair:
        return as_value(material_pair(r, key.name, key.need));
      case Type::kTable:
      case Type::kTableArray:
        break;  // read by the caller, as its own table
    }
    return std::nullopt;
  }

  void read_run(const toml::table& table) {
    read_keys(TableReader(diag_, table, deck::kRun), deck::kRun, scene_.run);
  }

  void read_contact(const toml::table& table) {
    const TableReader r(diag_, table, deck::kContact);
    const Accepted accepted = read_keys(r, deck::kContact, scene_.contact);
    // An invalid model (reported) turns the model-dependent checks of the materials off.
    model_.reset();
    if (accepted.has("model") || !r.has("model")) model_ = scene_.contact.model;
  }

  void read_material(const toml::table& table, std::size_t index) {
    const TableReader r(diag_, table, deck::kMaterial, index);
    MaterialSpec m;
    const Accepted accepted = read_keys(r, deck::kMaterial, m);
    if (accepted.has("name")) {
      const auto same = std::find(material_names_.begin(), material_names_.end(), m.name);
      if (m.name.empty() || m.name.find('.') != std::string::npos) {
        r.invalid("name", "must be a non-empty name without '.'");
        m.name.clear();
      } else if (same != material_names_.end()) {
        r.invalid("name",
                  fmt::format("already the name of material[{}]", same - material_names_.begin()));
        m.name.clear();
      }
    }
    read_elasticity(r, accepted, m);
    material_names_.push_back(m.name);  // "" for an invalid name: index stays aligned
    scene_.materials.push_back(std::move(m));
  }

  // Isotropic elasticity: G = E / (2 (1 + nu)), nu = E / (2 G) - 1; one of the two is given.
  static void read_elasticity(const TableReader& r, const Accepted& accepted, MaterialSpec& m) {
    const auto youngs = accepted.get<double>("youngs_modulus");
    if (r.has("poisson_ratio") && r.has("shear_modulus")) {
      r.error_at("shear_modulus",
                 fmt::format("{}: give poisson_ratio or shear_modulus, not both", r.path()));
    } else if (r.has("shear_modulus")) {
      const auto shear = accepted.get<double>("shear_modulus");
      if (!shear || !youngs) return;
      const double nu = *youngs / (2.0 * *shear) - 1.0;
      // The range of the poisson_ratio key, so that the resolved deck, which may write the
      // ratio instead, reads back (a shear modulus above E/2 was accepted and its resolved
      // deck refused: found by the fuzzer).
      if (nu >= 0.0 && nu < 0.5) {
        m.poisson_ratio = nu;
      } else {
        r.invalid("shear_modulus",
                  fmt::format("gives poisson_ratio = youngs_modulus / (2 shear_modulus) - 1 "
                              "= {:.6g}, which must be in [0, 0.5) ({:.6g} < shear_modulus "
                              "<= {:.6g})",
                              nu, *youngs / 3.0, *youngs / 2.0));
      }
    } else if (youngs) {
      m.shear_modulus = *youngs / (2.0 * (1.0 + m.poisson_ratio));
    }
  }

  // The valid material names, in deck order.
  std::vector<std::string> defined_materials() const {
    std::vector<std::string> names;
    for (const auto& name : material_names_) {
      if (!name.empty()) names.push_back(name);
    }
    return names;
  }

  // True when `name` (the value of `node`, shown as `path`) names a defined material.
  bool check_material_name(const toml::node& node, const std::string& path,
                           const std::string& name) {
    if (std::find(material_names_.begin(), material_names_.end(), name) != material_names_.end()) {
      return true;
    }
    if (material_names_.empty()) return false;  // "no [[material]]" is reported once
    const std::vector<std::string> defined = defined_materials();
    std::string message = fmt::format("{} = {}: no such material", path, quoted_string(name));
    if (const auto near = closest_match(name, defined)) {
      message += fmt::format("; did you mean {}?", quoted_string(*near));
    }
    message += defined.empty() ? " (no [[material]] has a valid name)"
                               : fmt::format(" (defined: {})", quoted_list(defined));
    diag_.error_at(node, message);
    return false;
  }

  std::optional<std::string> material_ref(const TableReader& r, std::string_view key, Need need) {
    auto name = r.string(key, need);
    if (name && !check_material_name(*r.find(key), r.path_of(key), *name)) name.reset();
    return name;
  }

  // ["a", "b"]: two defined material names (nullopt when absent or invalid, which is reported).
  std::optional<deck::Names> material_pair(const TableReader& r, std::string_view key, Need need) {
    const toml::node* node = r.find(key);
    if (node == nullptr) {
      if (need == Need::kRequired) r.missing(key, expected_text(Type::kMaterialPair, {}));
      return std::nullopt;
    }
    const auto* array = node->as_array();
    if (array == nullptr || array->size() != 2 || !array->get(0)->is_string() ||
        !array->get(1)->is_string()) {
      r.invalid(key, "expected " + expected_text(Type::kMaterialPair, {}));
      return std::nullopt;
    }
    deck::Names names(2);
    bool known = true;
    for (std::size_t i = 0; i < 2; ++i) {
      names[i] = array->get(i)->as_string()->get();
      known &=
          check_material_name(*array->get(i), fmt::format("{}[{}]", r.path_of(key), i), names[i]);
    }
    if (!known) return std::nullopt;
    return names;
  }

  void read_interaction(const toml::table& table, std::size_t index) {
    const TableReader r(diag_, table, deck::kInteraction, index);
    InteractionSpec spec;
    if (read_keys(r, deck::kInteraction, spec).has("materials")) {
      const auto pair = std::minmax(spec.material_a, spec.material_b);
      const auto key = std::make_pair(pair.first, pair.second);
      if (const auto seen = interaction_pairs_.find(key); seen != interaction_pairs_.end()) {
        r.invalid("materials", fmt::format("this pair already has interaction[{}]", seen->second));
      } else {
        interaction_pairs_.emplace(key, index);
      }
    }
    scene_.interactions.push_back(std::move(spec));
  }

  // The most sides of a polygonal drum and lifter bars in all: the thesis's drum has 16 sides
  // and 12 bars; a circle is sides = 0.
  static constexpr int kMaxDrumSides = 10000;
  static constexpr int kMaxLifterBars = 10000;

  void read_drum(const toml::table& table) {
    const TableReader r(diag_, table, deck::kDrum);
    DrumSpec& drum = scene_.drum;
    drum.present = true;
    const Accepted accepted = read_keys(r, deck::kDrum, drum);
    const auto radius = accepted.get<double>("radius");
    read_drum_speed(r, accepted, radius);
    if (const auto sides = accepted.get<std::int64_t>("sides");
        sides && (*sides == 1 || *sides == 2)) {
      r.invalid("sides", "must be 0 (a circle) or >= 3 (a regular polygon)");
    } else if (sides && *sides > kMaxDrumSides) {
      // The placement and feed checks walk the sides for every particle and the walls make one
      // element of each: sides = 2147483647 hung the reader (found with the fuzz target).
      r.invalid("sides", fmt::format("must be at most {} (a circle is sides = 0)", kMaxDrumSides));
      drum.sides = 0;  // the checks that follow see a circle
    }
    const auto lifters = r.table_array("lifter");
    for (std::size_t i = 0; i < lifters.size(); ++i) read_lifter(*lifters[i], i, radius);
  }

  // At most one of speed, speed_rpm and critical_fraction. The per-key pass stored the first
  // two (in rad/s); the critical fraction needs the gravity and the radius.
  void read_drum_speed(const TableReader& r, const Accepted& accepted,
                       std::optional<double> radius) {
    std::vector<std::string_view> speeds;
    for (const std::string_view key : {"speed", "speed_rpm", "critical_fraction"}) {
      if (r.has(key)) speeds.push_back(key);
    }
    if (speeds.size() > 1) {
      r.invalid(speeds[1], fmt::format("give only one of speed, speed_rpm and critical_fraction "
                                       "(found {})",
                                       and_list(speeds)));
      return;
    }
    const auto fraction = accepted.get<double>("critical_fraction");
    if (!fraction) return;
    // Classical critical speed w_c = sqrt(|g| / R): a point on the shell just stays on it.
    const double g = norm(scene_.run.gravity);
    if (g == 0.0) {
      r.invalid("critical_fraction", "needs a non-zero run.gravity (w_c = sqrt(|g| / R))");
    } else if (radius) {
      scene_.drum.speed = *fraction * std::sqrt(g / *radius);
    }
  }

  void read_lifter(const toml::table& table, std::size_t index, std::optional<double> radius) {
    const TableReader r(diag_, table, deck::kLifter, index);
    LifterSpec lifter;
    const auto height = read_keys(r, deck::kLifter, lifter).get<double>("height");
    if (height && radius && *height >= *radius) {
      r.invalid("height", fmt::format("must be < drum.radius = {}", *radius));
    }
    // Each bar is three wall elements and the checks walk every bar: count = 2147483647 hung
    // the reader and asked the walls for 2^31 x 3 elements (found with the fuzz target).
    int bars = 0;  // of the lifters before this one, at most kMaxLifterBars
    for (const LifterSpec& l : scene_.drum.lifters) bars += l.count;
    if (lifter.count > kMaxLifterBars - bars) {
      r.invalid("count", fmt::format("makes {} lifter bars in all; at most {} are allowed",
                                     std::int64_t{bars} + lifter.count, kMaxLifterBars));
      lifter.count = 0;  // the checks that follow see no bars
    }
    scene_.drum.lifters.push_back(std::move(lifter));
  }

  void read_particle(const toml::table& table, std::size_t index) {
    const TableReader r(diag_, table, deck::kParticle, index);
    ParticleSpec p;
    read_keys(r, deck::kParticle, p);
    p.source_line = r.line();
    scene_.particles.push_back(std::move(p));
  }

  void read_fill(const toml::table& table, std::size_t index) {
    const TableReader r(diag_, table, deck::kFill, index);
    FillSpec fill;
    fill.source_line = r.line();
    fill.index = static_cast<int>(index);
    const Accepted accepted = read_keys(r, deck::kFill, fill);
    std::vector<std::string_view> sources;
    for (const std::string_view key : {"count", "fill_fraction", "file"}) {
      if (r.has(key)) sources.push_back(key);
    }
    if (sources.size() != 1) {
      r.error(sources.empty()
                  ? fmt::format("{} needs one of count, fill_fraction and file", r.path())
                  : fmt::format("{}: give only one of count, fill_fraction and file (found {})",
                                r.path(), and_list(sources)));
    }
    if (sources.size() == 1 && sources[0] == "file") {
      for (const std::string_view key :
           {"radius", "radius_min", "radius_max", "region", "box_min", "box_max"}) {
        if (r.has(key))
          r.invalid(key, "not used by a fill from a file (the file gives each particle)");
      }
      if (const auto file = accepted.get<std::string>("file")) read_fill_file(r, *file, fill);
      return;
    }
    require(r, deck::kFill, "material");  // a file may name each row's material instead
    if (accepted.has("fill_fraction") && !scene_.drum.present) {
      r.invalid("fill_fraction", "needs a [drum] (it is a fraction of the drum's area)");
    }
    read_fill_radii(r, accepted);
    read_fill_region(r, accepted, fill);
    scene_.fills.push_back(std::move(fill));
  }

  // radius (mono-disperse) or radius_min and radius_max (uniform in r between them).
  static void read_fill_radii(const TableReader& r, const Accepted& accepted) {
    const bool has_range = r.has("radius_min") || r.has("radius_max");
    if (r.has("radius") && has_range) {
      r.error(fmt::format("{}: give radius, or radius_min and radius_max, not both", r.path()));
    } else if (has_range) {
      require(r, deck::kFill, "radius_min");
      require(r, deck::kFill, "radius_max");
      const auto lo = accepted.get<double>("radius_min");
      const auto hi = accepted.get<double>("radius_max");
      if (lo && hi && *lo > *hi) {
        r.invalid("radius_min", fmt::format("must be <= radius_max = {}", r.shown("radius_max")));
      }
    } else if (!r.has("radius")) {
      r.error(fmt::format("{} needs radius, or radius_min and radius_max (m, > 0)", r.path()));
    }
  }

  void read_fill_region(const TableReader& r, const Accepted& accepted, const FillSpec& fill) {
    if (r.has("region") && !accepted.has("region")) return;  // reported
    if (fill.region == FillRegion::kBox) {
      require(r, deck::kFill, "box_min");
      require(r, deck::kFill, "box_max");
      const auto lo = accepted.get<Vec2>("box_min");
      const auto hi = accepted.get<Vec2>("box_max");
      if (lo && hi && !(lo->x < hi->x && lo->y < hi->y)) {
        r.invalid("box_max", fmt::format("must be above and to the right of box_min = {}",
                                         r.shown("box_min")));
      }
      return;
    }
    for (const std::string_view key : {"box_min", "box_max"}) {
      if (r.has(key)) r.invalid(key, "only used with region = \"box\"");
    }
    if (scene_.drum.present) return;
    if (r.has("region")) {
      r.invalid("region", "needs a [drum]; without one, use region = \"box\"");
    } else {
      r.error(
          fmt::format("{}: the default region \"bottom\" needs a [drum]; without one, use "
                      "region = \"box\" with box_min and box_max",
                      r.path()));
    }
  }

  // A [[fill]] file: a CSV packing with a header row; relative paths are from the deck's folder.
  void read_fill_file(const TableReader& r, const std::string& file, FillSpec& fill) {
    const fs::path given(file);
    const fs::path path = given.is_absolute() ? given : deck_dir_ / given;
    const std::string shown = path.lexically_normal().string();
    std::error_code ec;
    fill.file = fs::absolute(path, ec).lexically_normal().string();
    std::FILE* stream = std::fopen(path.c_str(), "rb");
    const int open_errno = errno;
    if (stream == nullptr || fs::is_directory(path, ec)) {
      r.invalid("file",
                fmt::format("cannot open {}: {}", shown,
                            stream == nullptr ? std::strerror(open_errno) : "it is a directory"));
      if (stream != nullptr) std::fclose(stream);
      return;
    }
    std::string text;
    if (const int read_errno = read_and_close(stream, text); read_errno != 0) {
      r.invalid("file", fmt::format("cannot read {}: {}", shown, std::strerror(read_errno)));
      return;
    }
    const CsvPacking packing =
        read_particle_csv(text, shown, defined_materials(),
                          CsvDefaults{fill.material, fill.velocity}, r.path_of("file"));
    for (const std::string& message : packing.file_errors) r.invalid("file", shown + " " + message);
    for (const std::string& message : packing.errors) diag_.add(message);
    if (!packing.has_material_column && fill.material.empty() && !r.has("material")) {
      r.error(fmt::format("{}.material is required: {} has no material column", r.path(), shown));
    }
    if (!packing.errors.empty() || !packing.file_errors.empty() || packing.particles.empty()) {
      return;
    }
    fill.count = static_cast<std::int64_t>(packing.particles.size());
    file_rows_.push_back({scene_.particles.size(), packing.particles.size(),
                          static_cast<std::size_t>(fill.index), shown});
    scene_.where[fmt::format("{}.csv", r.path())] = shown;
    scene_.particles.insert(scene_.particles.end(), packing.particles.begin(),
                            packing.particles.end());
    scene_.file_fills.push_back(std::move(fill));
  }

  void read_wall(const toml::table& table, std::size_t index) {
    const TableReader r(diag_, table, deck::kWall, index);
    WallSpec wall;
    const Accepted accepted = read_keys(r, deck::kWall, wall);
    const auto from = accepted.get<Vec2>("from");
    const auto to = accepted.get<Vec2>("to");
    if (from && to && *from == *to) {
      r.invalid("to", "must differ from wall.from (a wall has a length)");
    }
    scene_.walls.push_back(std::move(wall));
  }

  void read_breakage(const toml::table& table) {
    const TableReader r(diag_, table, deck::kBreakage);
    BreakageSpec& b = scene_.breakage;
    b.present = true;
    const Accepted accepted = read_keys(r, deck::kBreakage, b);
    if (accepted.has("fragments_max") && b.fragments_max < b.fragments_min) {
      r.invalid("fragments_max",
                fmt::format("must be at least fragments_min = {}", b.fragments_min));
    }
  }

  void read_feed(const toml::table& table) {
    const TableReader r(diag_, table, deck::kFeed);
    FeedSpec& f = scene_.feed;
    f.present = true;
    const Accepted accepted = read_keys(r, deck::kFeed, f);
    if (accepted.has("period") == accepted.has("mass_rate")) {
      r.invalid(accepted.has("period") ? "mass_rate" : "period",
                "give exactly one of period (s between particles) and mass_rate (kg/s)");
    }
    if (accepted.has("radius_max") && accepted.has("radius_min") && f.radius_max < f.radius_min) {
      r.invalid("radius_max", fmt::format("must be at least radius_min = {} m", f.radius_min));
    }
    if (accepted.has("point") && !scene_.drum.present) {
      r.invalid("point", "a feed needs a [drum]");
    } else if (!scene_.drum.present) {
      r.invalid("material", "a feed needs a [drum] to place its particles in");
    } else if (accepted.has("point") && accepted.has("radius_max") && scene_.drum.radius > 0.0) {
      check_feed_point(r, f);
    }
  }

  // A fed particle of the largest radius fits at the point: inside the shell, clear of the
  // lifter bars (else it would fall forever outside the drum, or start inside a bar).
  void check_feed_point(const TableReader& r, const FeedSpec& f) {
    const DrumSpec& d = scene_.drum;
    const double clearance = DrumGeometry(d).shell_clearance(f.point);
    if (clearance < f.radius_max) {
      r.invalid("point",
                fmt::format("a fed particle of radius_max {:g} m {} the drum (radius {:g} "
                            "m about [{:g}, {:g}]); give a point at least radius_max "
                            "inside the shell",
                            f.radius_max,
                            clearance <= -f.radius_max ? "lies outside" : "straddles the shell of",
                            d.radius, d.center.x, d.center.y));
    } else if (const auto bar = DrumGeometry(d).bar_overlap(f.point, f.radius_max)) {
      r.invalid("point", fmt::format("a fed particle of radius_max {:g} m {} bar {} of "
                                     "drum.lifter[{}]; give a point clear of the lifters",
                                     f.radius_max, bar->inside ? "lies inside" : "overlaps",
                                     bar->bar, bar->lifter));
    }
  }

  void read_sieve(const toml::table& table) {
    const TableReader r(diag_, table, deck::kSieve);
    SieveSpec& s = scene_.sieve;
    s.present = true;
    const Accepted accepted = read_keys(r, deck::kSieve, s);
    if (!(s.box_max.x > s.box_min.x && s.box_max.y > s.box_min.y)) {
      r.invalid(accepted.has("box_max") ? "box_max" : "box_min",
                fmt::format("the zone must be above and right of box_min = [{}, {}]", s.box_min.x,
                            s.box_min.y));
    }
  }

  void read_output(const toml::table& table) {
    const TableReader r(diag_, table, deck::kOutput);
    const OutputSpec& output = scene_.output;
    const Accepted accepted = read_keys(r, deck::kOutput, scene_.output);
    if (accepted.has("directory") && output.directory.empty()) {
      r.invalid("directory", "must not be empty");
    }
  }

  const toml::table& root_;
  Diagnostics& diag_;
  fs::path deck_dir_;
  Scene scene_;
  // The deck's contact model; unset when it is invalid (model-dependent checks are skipped).
  std::optional<ContactModelKind> model_ = ContactModelKind::kHertzMindlin;
  std::vector<std::string> material_names_;  // by index; "" where the name was invalid
  std::map<std::pair<std::string, std::string>, std::size_t> interaction_pairs_;
  std::vector<FileRows> file_rows_;  // the particles each [[fill]] file added, in order
};

// Where the deck gave the values that the checks after reading may refuse (Scene::where):
// the count and velocities of what the core places, the duration, the drum's speed.
void record_where(const toml::table& root, const Diagnostics& diag, Scene& scene) {
  const auto put = [&](const std::string& key, const toml::node* node) {
    if (node != nullptr) scene.where[key] = diag.where(*node);
  };
  for (const char* key : {"run.duration", "run.dt", "drum.speed", "drum.speed_rpm",
                          "drum.critical_fraction", "feed.velocity", "output.directory"}) {
    put(key, root.at_path(key).node());
  }
  const auto each = [&](std::string_view name, std::initializer_list<std::string_view> keys) {
    const toml::array* tables = root.get_as<toml::array>(name);
    for (std::size_t i = 0; tables != nullptr && i < tables->size(); ++i) {
      const toml::table* table = tables->get(i)->as_table();
      if (table == nullptr) continue;
      for (const std::string_view key : keys) {
        put(fmt::format("{}[{}].{}", name, i, key), table->get(key));
      }
    }
  };
  each("particle", {"velocity", "spin"});
  each("fill", {"count", "fill_fraction", "radius", "radius_max", "velocity", "file"});
  each("wall", {"velocity"});
}

// For a syntax error at `line` (1-based): the line as the deck wrote it and the table header
// above it, so that the message shows the key: " (in [run]: duration = 1.0.0)".
std::string syntax_context(std::string_view text, std::size_t line) {
  std::string_view table, here;
  std::size_t n = 1;
  for (std::size_t start = 0; start <= text.size() && n <= line; ++n) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    const std::string_view row = trim(text.substr(start, end - start));
    if (n == line) {
      here = row;
    } else if (row.starts_with('[')) {
      table = trim(row.substr(0, row.find('#')));
    }
    start = end + 1;
  }
  if (here.empty()) return "";
  constexpr std::size_t kShown = 60;
  const std::string shown =
      std::string(here.substr(0, kShown)) + (here.size() > kShown ? "..." : "");
  if (table.empty() || here.starts_with('[')) return fmt::format(" (the line: {})", shown);
  return fmt::format(" (in {}: {})", table, shown);
}

}  // namespace

Scene parse_deck_string(const std::string& text, const std::string& path_for_messages,
                        const std::vector<std::string>& overrides) {
  toml::table root;
  try {
    root = toml::parse(text, std::string_view(path_for_messages));
  } catch (const toml::parse_error& e) {
    const auto& at = e.source().begin;
    throw InputError(fmt::format("{}:{}:{}: error: {}{}", path_for_messages, at.line, at.column,
                                 e.description(), syntax_context(text, at.line)));
  }
  Origins origins;
  Diagnostics diag(path_for_messages, origins);
  diag.set_root(&root);
  diag.set_source(text);
  for (const std::string& option : overrides) apply_override(root, option, origins, diag);

  const fs::path deck_dir = fs::path(path_for_messages).parent_path();
  Scene scene = DeckParser(root, diag, deck_dir.empty() ? fs::path(".") : deck_dir).parse();
  if (!diag.messages().empty()) throw InputError(std::move(diag.messages()));
  scene.deck_path = path_for_messages;
  if (const toml::node* dt = root.at_path("run.dt").node()) scene.run.dt_where = diag.where(*dt);
  record_where(root, diag, scene);
  return scene;
}

Scene load_deck(const std::string& path, const std::vector<std::string>& overrides) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    throw InputError(fmt::format("{}: error: cannot open deck: it is a directory", path));
  }
  std::FILE* stream = std::fopen(path.c_str(), "rb");
  if (stream == nullptr) {
    throw InputError(fmt::format("{}: error: cannot open deck: {}", path, std::strerror(errno)));
  }
  std::string text;
  if (const int read_errno = read_and_close(stream, text); read_errno != 0) {
    throw InputError(
        fmt::format("{}: error: cannot read deck: {}", path, std::strerror(read_errno)));
  }
  return parse_deck_string(text, path, overrides);
}

}  // namespace dem2d
