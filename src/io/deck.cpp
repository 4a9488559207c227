// Deck reader: TOML text -> --set overrides -> validation -> Scene (docs/input.md).
//
// One toml::table goes through three stages. The overrides are applied to the tree, and every
// node they make is remembered with the option's text (Origins), so that a message about it
// names the option. Then a DeckParser reads every table through a TableReader, which checks
// types and ranges, reports unknown keys with the closest valid one, and adds every message to
// one Diagnostics. Last come the checks across tables (material references, particle sources).
// Nothing throws before all of that has run, except a TOML syntax error (no tree to check).
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
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <utility>

#include "core/errors.hpp"
#include "io/deck_schema.hpp"
#include "io/particle_csv.hpp"
#include "io/text.hpp"

namespace dem2d {
namespace {

namespace fs = std::filesystem;
using Keys = std::span<const std::string_view>;
using deck::Choice;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// ---------------------------------------------------------------------------------------------
// Text helpers

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

// ---------------------------------------------------------------------------------------------
// TableReader: typed, checked reads of one table's keys

// The allowed interval of a number, and its wording ("> 0", "in (0, 1]").
struct Bound {
  double lo = -kInfinity;
  double hi = kInfinity;
  bool lo_open = false;
  bool hi_open = false;

  bool contains(double v) const {
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  bool unbounded() const { return lo == -kInfinity && hi == kInfinity; }
  std::string text() const {
    if (hi == kInfinity) return fmt::format("{} {}", lo_open ? ">" : ">=", lo);
    if (lo == -kInfinity) return fmt::format("{} {}", hi_open ? "<" : "<=", hi);
    return fmt::format("in {}{}, {}{}", lo_open ? '(' : '[', lo, hi, hi_open ? ')' : ']');
  }
};

constexpr Bound kAnyNumber{};
constexpr Bound kPositive{0.0, kInfinity, true, false};      // > 0
constexpr Bound kNonNegative{0.0, kInfinity, false, false};  // >= 0
constexpr Bound kRestitution{0.0, 1.0, true, false};         // (0, 1]
constexpr Bound kUnitFraction{0.0, 1.0, true, false};        // (0, 1]
constexpr Bound kPoissonRatio{0.0, 0.5, false, true};        // [0, 0.5): isotropic, compressible
constexpr Bound kFillFraction{0.0, 0.9, true, true};         // (0, 0.9): room left to place them
constexpr Bound kAtLeastOne{1.0, kInfinity, false, false};   // >= 1 (integers)

enum class Need { kOptional, kRequired };

template <class T>
void set_if(T& target, const std::optional<T>& value) {
  if (value) target = *value;
}

class TableReader {
 public:
  // `path`: the table's dotted path in messages ("material[1]", "" for the root); `header`: the
  // table as a deck writes it ("[[material]]"); `schema`: its path without indices
  // ("drum.lifter"), for naming unknown sub-tables.
  TableReader(Diagnostics& diag, const toml::table& table, std::string path, std::string header,
              std::string schema, Keys valid_keys)
      : diag_(diag),
        table_(table),
        path_(std::move(path)),
        header_(std::move(header)),
        schema_(std::move(schema)),
        valid_keys_(valid_keys) {}

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

  std::optional<double> number(std::string_view key, const Bound& bound = kAnyNumber,
                               Need need = Need::kOptional) const {
    const std::string expected = bound.unbounded() ? "a number" : "a number " + bound.text();
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
    const std::string expected = "an integer " + bound.text();
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
      if (need == Need::kRequired) missing(key, "a string");
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
      if (need == Need::kRequired) missing(key, "an array of two numbers [x, y]");
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
  template <class E, std::size_t N>
  std::optional<E> choice(std::string_view key, const std::array<Choice<E>, N>& choices) const {
    const toml::node* node = find(key);
    if (node == nullptr) return std::nullopt;
    std::vector<std::string_view> names;
    for (const auto& c : choices) names.push_back(c.name);
    if (const auto* s = node->as_string()) {
      for (const auto& c : choices) {
        if (c.name == s->get()) return c.value;
      }
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
      const auto near = closest_match(name, valid_keys_);
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
  Keys valid_keys_;
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

bool is_table_array(std::string_view dotted) {
  return std::find(deck::kTableArrays.begin(), deck::kTableArrays.end(), dotted) !=
         deck::kTableArrays.end();
}

bool is_index(std::string_view s) {
  return !s.empty() && s.size() < 10 &&
         std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
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

// Applies one override; a problem with the option itself (not with the value it sets, which
// the validation reports) is an error naming the option.
void apply_override(toml::table& root, const std::string& option, Origins& origins,
                    Diagnostics& diag) {
  const std::string where = "--set " + option;
  const auto fail = [&](std::string_view message) { diag.error_in(where, message); };
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
    if (is_table_array(schema)) {
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
  if (is_table_array(last_schema)) {
    fail(fmt::format("cannot set all of [[{}]]; set one key of one element: {}.INDEX.KEY",
                     last_schema, last_schema));
    return;
  }
  if (const toml::node* old = table->get(last)) forget_origin(*old, origins);
  assign_override_value(*table, last, value);
  record_origin(*table->get(last), where, origins);
}

// ---------------------------------------------------------------------------------------------
// DeckParser: the tree -> a Scene, every table and every cross-reference checked

class DeckParser {
 public:
  DeckParser(const toml::table& root, Diagnostics& diag, fs::path deck_dir)
      : root_(root), diag_(diag), deck_dir_(std::move(deck_dir)) {}

  Scene parse() {
    const TableReader root(diag_, root_, "", "", "", deck::kRootKeys);
    root.check_unknown_keys();
    set_if(scene_.title, root.string("title"));
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
    const auto walls = root.table_array("wall");
    for (std::size_t i = 0; i < walls.size(); ++i) read_wall(*walls[i], i);
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
  void read_run(const toml::table& table) {
    const TableReader r(diag_, table, "run", "[run]", "run", deck::kRunKeys);
    r.check_unknown_keys();
    RunSpec& run = scene_.run;
    set_if(run.duration, r.number("duration", kPositive));
    if (const toml::node* dt = r.find("dt")) {
      if (dt->is_string() && dt->as_string()->get() == "auto") {
        run.dt_auto = true;
        run.dt = 0.0;
      } else if (!dt->is_number()) {
        r.invalid("dt", "expected a number > 0 (s) or \"auto\"");
      } else if (const auto value = r.number("dt", kPositive)) {
        run.dt_auto = false;
        run.dt = *value;
      }
    }
    set_if(run.integrator, r.choice("integrator", deck::kIntegrators));
    set_if(run.tolerance, r.number("tolerance", kPositive));
    if (const auto passes = r.integer("max_passes", kAtLeastOne)) {
      run.max_passes = static_cast<int>(*passes);
    }
    if (const auto seed = r.integer("seed", kNonNegative, Need::kOptional, INT64_MAX)) {
      run.seed = static_cast<std::uint64_t>(*seed);
    }
    set_if(run.gravity, r.pair("gravity"));
    set_if(run.skin, r.number("skin", kNonNegative));
    set_if(run.dt_safety, r.number("dt_safety", kUnitFraction));
    set_if(run.allow_unsafe_dt, r.boolean("allow_unsafe_dt"));
    if (const auto sectors = r.integer("sectors_per_rank", kAtLeastOne, Need::kOptional, 4096)) {
      run.sectors_per_rank = static_cast<int>(*sectors);
    }
    set_if(run.repartition_threshold, r.number("repartition_threshold", kPositive));
  }

  void read_contact(const toml::table& table) {
    const TableReader r(diag_, table, "contact", "[contact]", "contact", deck::kContactKeys);
    r.check_unknown_keys();
    ContactSpec& contact = scene_.contact;
    if (r.has("model")) {
      model_ = r.choice("model", deck::kContactModels);
      set_if(contact.model, model_);
    }
    set_if(contact.rolling, r.choice("rolling", deck::kRollingModels));
    set_if(contact.rolling_damping, r.number("rolling_damping", kNonNegative));
  }

  // The coefficients only some contact models take: restitution (hertz-mindlin, linear), the
  // damping ratios (thesis) and normal_stiffness (linear). Another model's coefficient is an
  // error rather than silently unused. Unknown model (already reported): anything goes.
  bool model_takes(std::string_view key) const {
    if (!model_) return true;
    if (key == "restitution") return *model_ != ContactModelKind::kThesis;
    if (key == "damping_normal" || key == "damping_tangential") {
      return *model_ == ContactModelKind::kThesis;
    }
    if (key == "normal_stiffness") return *model_ == ContactModelKind::kLinear;
    return true;
  }

  static std::string_view model_coefficients(ContactModelKind model) {
    switch (model) {
      case ContactModelKind::kHertzMindlin:
        return "restitution";
      case ContactModelKind::kThesis:
        return "damping_normal and damping_tangential";
      case ContactModelKind::kLinear:
        return "restitution and normal_stiffness";
    }
    return "";
  }

  // Reads a model-dependent coefficient, or reports it as not used by the model.
  std::optional<double> model_coefficient(const TableReader& r, std::string_view key,
                                          const Bound& bound) const {
    if (!r.has(key)) return std::nullopt;
    if (!model_takes(key)) {
      r.invalid(key, fmt::format("not used by contact.model = \"{}\", which takes {}",
                                 deck::choice_name(deck::kContactModels, *model_),
                                 model_coefficients(*model_)));
      return std::nullopt;
    }
    return r.number(key, bound);
  }

  void read_material(const toml::table& table, std::size_t index) {
    const TableReader r(diag_, table, fmt::format("material[{}]", index), "[[material]]",
                        "material", deck::kMaterialKeys);
    r.check_unknown_keys();
    MaterialSpec m;
    if (const auto name = r.string("name", Need::kRequired)) {
      const auto same = std::find(material_names_.begin(), material_names_.end(), *name);
      if (name->empty() || name->find('.') != std::string::npos) {
        r.invalid("name", "must be a non-empty name without '.'");
      } else if (same != material_names_.end()) {
        r.invalid("name",
                  fmt::format("already the name of material[{}]", same - material_names_.begin()));
      } else {
        m.name = *name;
      }
    }
    const auto density = r.number("density", kPositive, Need::kRequired);
    const auto youngs = r.number("youngs_modulus", kPositive, Need::kRequired);
    set_if(m.density, density);
    set_if(m.youngs_modulus, youngs);
    // Isotropic elasticity: G = E / (2 (1 + nu)), nu = E / (2 G) - 1; one of the two is given.
    if (r.has("poisson_ratio") && r.has("shear_modulus")) {
      r.error_at("shear_modulus",
                 fmt::format("{}: give poisson_ratio or shear_modulus, not both", r.path()));
    } else if (r.has("shear_modulus")) {
      const auto shear = r.number("shear_modulus", kPositive);
      if (shear && youngs) {
        const double nu = *youngs / (2.0 * *shear) - 1.0;
        if (nu >= -1.0 && nu < 0.5) {
          m.shear_modulus = *shear;
          m.poisson_ratio = nu;
        } else {
          r.invalid("shear_modulus",
                    fmt::format("gives poisson_ratio = youngs_modulus / (2 shear_modulus) - 1 "
                                "= {}, which must be in [-1, 0.5) (shear_modulus > {})",
                                nu, *youngs / 3.0));
        }
      }
    } else {
      set_if(m.poisson_ratio, r.number("poisson_ratio", kPoissonRatio));
      if (youngs) m.shear_modulus = *youngs / (2.0 * (1.0 + m.poisson_ratio));
    }
    set_if(m.restitution, model_coefficient(r, "restitution", kRestitution));
    set_if(m.damping_normal, model_coefficient(r, "damping_normal", kNonNegative));
    set_if(m.damping_tangential, model_coefficient(r, "damping_tangential", kNonNegative));
    set_if(m.normal_stiffness, model_coefficient(r, "normal_stiffness", kPositive));
    set_if(m.sliding_friction, r.number("sliding_friction", kNonNegative));
    set_if(m.rolling_friction, r.number("rolling_friction", kNonNegative));
    material_names_.push_back(m.name);  // "" for an invalid name: index stays aligned
    scene_.materials.push_back(std::move(m));
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

  void read_interaction(const toml::table& table, std::size_t index) {
    const TableReader r(diag_, table, fmt::format("interaction[{}]", index), "[[interaction]]",
                        "interaction", deck::kInteractionKeys);
    r.check_unknown_keys();
    InteractionSpec spec;
    if (const toml::node* node = r.find("materials")) {
      const auto* array = node->as_array();
      if (array == nullptr || array->size() != 2 || !array->get(0)->is_string() ||
          !array->get(1)->is_string()) {
        r.invalid("materials", "expected two material names [\"a\", \"b\"]");
      } else {
        bool known = true;
        std::string names[2];
        for (std::size_t i = 0; i < 2; ++i) {
          names[i] = array->get(i)->as_string()->get();
          known &= check_material_name(*array->get(i), fmt::format("{}.materials[{}]", r.path(), i),
                                       names[i]);
        }
        if (known) {
          auto pair = std::minmax(names[0], names[1]);
          const auto key = std::make_pair(pair.first, pair.second);
          if (const auto seen = interaction_pairs_.find(key); seen != interaction_pairs_.end()) {
            r.invalid("materials",
                      fmt::format("this pair already has interaction[{}]", seen->second));
          } else {
            interaction_pairs_.emplace(key, index);
          }
          spec.material_a = names[0];
          spec.material_b = names[1];
        }
      }
    } else {
      r.missing("materials", "two material names [\"a\", \"b\"]");
    }
    spec.restitution = model_coefficient(r, "restitution", kRestitution);
    spec.damping_normal = model_coefficient(r, "damping_normal", kNonNegative);
    spec.damping_tangential = model_coefficient(r, "damping_tangential", kNonNegative);
    spec.sliding_friction = r.number("sliding_friction", kNonNegative);
    spec.rolling_friction = r.number("rolling_friction", kNonNegative);
    scene_.interactions.push_back(std::move(spec));
  }

  void read_drum(const toml::table& table) {
    const TableReader r(diag_, table, "drum", "[drum]", "drum", deck::kDrumKeys);
    r.check_unknown_keys();
    DrumSpec& drum = scene_.drum;
    drum.present = true;
    const auto radius = r.number("radius", kPositive, Need::kRequired);
    set_if(drum.radius, radius);
    set_if(drum.center, r.pair("center"));

    std::vector<std::string_view> speeds;
    for (const std::string_view key : {"speed", "speed_rpm", "critical_fraction"}) {
      if (r.has(key)) speeds.push_back(key);
    }
    if (speeds.size() > 1) {
      r.error_at(speeds[1], fmt::format("drum: give only one of speed, speed_rpm and "
                                        "critical_fraction (found {})",
                                        and_list(speeds)));
    } else if (speeds.size() == 1 && speeds[0] == "speed") {
      set_if(drum.speed, r.number("speed"));  // rad/s, counter-clockwise positive
    } else if (speeds.size() == 1 && speeds[0] == "speed_rpm") {
      if (const auto rpm = r.number("speed_rpm")) drum.speed = *rpm * kRadPerSecondPerRpm;
    } else if (speeds.size() == 1) {
      // Classical critical speed w_c = sqrt(|g| / R): a point on the shell just stays on it.
      const auto fraction = r.number("critical_fraction");
      const double g = norm(scene_.run.gravity);
      if (fraction && g == 0.0) {
        r.invalid("critical_fraction", "needs a non-zero run.gravity (w_c = sqrt(|g| / R))");
      } else if (fraction && radius) {
        drum.speed = *fraction * std::sqrt(g / *radius);
      }
    }
    set_if(drum.ramp_time, r.number("ramp_time", kNonNegative));
    if (const auto sides = r.integer("sides", kNonNegative)) {
      if (*sides == 1 || *sides == 2) {
        r.invalid("sides", "must be 0 (a circle) or >= 3 (a regular polygon)");
      } else {
        drum.sides = static_cast<int>(*sides);
      }
    }
    if (const auto degrees = r.number("angle")) drum.angle = *degrees * kRadiansPerDegree;
    set_if(drum.material, material_ref(r, "material", Need::kRequired));
    const auto lifters = r.table_array("lifter");
    for (std::size_t i = 0; i < lifters.size(); ++i) read_lifter(*lifters[i], i, radius);
  }

  void read_lifter(const toml::table& table, std::size_t index, std::optional<double> radius) {
    const TableReader r(diag_, table, fmt::format("drum.lifter[{}]", index), "[[drum.lifter]]",
                        "drum.lifter", deck::kLifterKeys);
    r.check_unknown_keys();
    LifterSpec lifter;
    if (const auto count = r.integer("count", kAtLeastOne, Need::kRequired)) {
      lifter.count = static_cast<int>(*count);
    }
    if (const auto height = r.number("height", kPositive, Need::kRequired)) {
      if (radius && *height >= *radius) {
        r.invalid("height", fmt::format("must be < drum.radius = {}", *radius));
      } else {
        lifter.height = *height;
      }
    }
    set_if(lifter.width, r.number("width", kPositive, Need::kRequired));
    if (const auto degrees = r.number("angle")) lifter.angle = *degrees * kRadiansPerDegree;
    set_if(lifter.material, material_ref(r, "material", Need::kOptional));
    scene_.drum.lifters.push_back(std::move(lifter));
  }

  void read_particle(const toml::table& table, std::size_t index) {
    const TableReader r(diag_, table, fmt::format("particle[{}]", index), "[[particle]]",
                        "particle", deck::kParticleKeys);
    r.check_unknown_keys();
    ParticleSpec p;
    set_if(p.material, material_ref(r, "material", Need::kRequired));
    set_if(p.radius, r.number("radius", kPositive, Need::kRequired));
    set_if(p.position, r.pair("position", Need::kRequired));
    set_if(p.velocity, r.pair("velocity"));
    set_if(p.spin, r.number("spin"));
    p.source_line = r.line();
    scene_.particles.push_back(std::move(p));
  }

  void read_fill(const toml::table& table, std::size_t index) {
    const TableReader r(diag_, table, fmt::format("fill[{}]", index), "[[fill]]", "fill",
                        deck::kFillKeys);
    r.check_unknown_keys();
    FillSpec fill;
    fill.source_line = r.line();
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
    const bool is_file = sources.size() == 1 && sources[0] == "file";
    set_if(fill.material, material_ref(r, "material", is_file ? Need::kOptional : Need::kRequired));
    set_if(fill.velocity, r.pair("velocity"));
    if (is_file) {
      for (const std::string_view key :
           {"radius", "radius_min", "radius_max", "region", "box_min", "box_max"}) {
        if (r.has(key))
          r.invalid(key, "not used by a fill from a file (the file gives each particle)");
      }
      if (const auto file = r.string("file")) read_fill_file(r, *file, fill);
      return;
    }
    if (const auto count = r.integer("count", kAtLeastOne, Need::kOptional, INT64_MAX)) {
      fill.count = *count;
    }
    if (r.has("fill_fraction")) {
      const auto fraction = r.number("fill_fraction", kFillFraction);
      if (fraction && !scene_.drum.present) {
        r.invalid("fill_fraction", "needs a [drum] (it is a fraction of the drum's area)");
      } else {
        set_if(fill.fill_fraction, fraction);
      }
    }
    read_fill_radii(r, fill);
    read_fill_region(r, fill);
    scene_.fills.push_back(std::move(fill));
  }

  // radius (mono-disperse) or radius_min and radius_max (uniform in r between them).
  void read_fill_radii(const TableReader& r, FillSpec& fill) {
    const bool has_range = r.has("radius_min") || r.has("radius_max");
    if (r.has("radius") && has_range) {
      r.error(fmt::format("{}: give radius, or radius_min and radius_max, not both", r.path()));
    } else if (r.has("radius")) {
      if (const auto radius = r.number("radius", kPositive)) {
        fill.radius_min = fill.radius_max = *radius;
      }
    } else if (has_range) {
      const auto lo = r.number("radius_min", kPositive, Need::kRequired);
      const auto hi = r.number("radius_max", kPositive, Need::kRequired);
      if (lo && hi && *lo > *hi) {
        r.invalid("radius_min", fmt::format("must be <= radius_max = {}", r.shown("radius_max")));
      } else if (lo && hi) {
        fill.radius_min = *lo;
        fill.radius_max = *hi;
      }
    } else {
      r.error(fmt::format("{} needs radius, or radius_min and radius_max (m, > 0)", r.path()));
    }
  }

  void read_fill_region(const TableReader& r, FillSpec& fill) {
    const auto region = r.choice("region", deck::kFillRegions);
    if (r.has("region") && !region) return;  // reported
    set_if(fill.region, region);
    if (fill.region == FillRegion::kBox) {
      const auto lo = r.pair("box_min", Need::kRequired);
      const auto hi = r.pair("box_max", Need::kRequired);
      if (lo && hi && !(lo->x < hi->x && lo->y < hi->y)) {
        r.invalid("box_max", fmt::format("must be above and to the right of box_min = {}",
                                         r.shown("box_min")));
      } else if (lo && hi) {
        fill.box_min = *lo;
        fill.box_max = *hi;
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
    char buffer[65536];
    for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, stream)) > 0;)
      text.append(buffer, n);
    const bool failed = std::ferror(stream) != 0;
    const int read_errno = errno;
    std::fclose(stream);
    if (failed) {
      r.invalid("file", fmt::format("cannot read {}: {}", shown, std::strerror(read_errno)));
      return;
    }
    const CsvPacking packing = read_particle_csv(text, shown, defined_materials(),
                                                 CsvDefaults{fill.material, fill.velocity});
    for (const std::string& message : packing.errors) diag_.add(message);
    if (!packing.has_material_column && fill.material.empty() && !r.has("material")) {
      r.error(fmt::format("{}.material is required: {} has no material column", r.path(), shown));
    }
    if (!packing.errors.empty() || packing.particles.empty()) return;
    fill.count = static_cast<std::int64_t>(packing.particles.size());
    scene_.particles.insert(scene_.particles.end(), packing.particles.begin(),
                            packing.particles.end());
    scene_.file_fills.push_back(std::move(fill));
  }

  void read_wall(const toml::table& table, std::size_t index) {
    const TableReader r(diag_, table, fmt::format("wall[{}]", index), "[[wall]]", "wall",
                        deck::kWallKeys);
    r.check_unknown_keys();
    WallSpec wall;
    const auto from = r.pair("from", Need::kRequired);
    const auto to = r.pair("to", Need::kRequired);
    if (from && to && *from == *to) {
      r.invalid("to", "must differ from wall.from (a wall has a length)");
    }
    set_if(wall.from, from);
    set_if(wall.to, to);
    set_if(wall.material, material_ref(r, "material", Need::kRequired));
    set_if(wall.velocity, r.pair("velocity"));
    scene_.walls.push_back(std::move(wall));
  }

  void read_output(const toml::table& table) {
    const TableReader r(diag_, table, "output", "[output]", "output", deck::kOutputKeys);
    r.check_unknown_keys();
    OutputSpec& output = scene_.output;
    if (const auto directory = r.string("directory")) {
      if (directory->empty()) {
        r.invalid("directory", "must not be empty");
      } else {
        output.directory = *directory;
      }
    }
    set_if(output.series_interval, r.number("series_interval", kPositive));
    set_if(output.snapshot_interval, r.number("snapshot_interval", kNonNegative));
    if (const auto interval = r.number("checkpoint_interval", kNonNegative)) {
      if (*interval > 0.0) {
        r.invalid("checkpoint_interval", "checkpoints are not implemented yet; use 0");
      }
    }
    set_if(output.progress_interval, r.number("progress_interval", kPositive));
  }

  const toml::table& root_;
  Diagnostics& diag_;
  fs::path deck_dir_;
  Scene scene_;
  // The deck's contact model; unset when it is invalid (model-dependent checks are skipped).
  std::optional<ContactModelKind> model_ = ContactModelKind::kHertzMindlin;
  std::vector<std::string> material_names_;  // by index; "" where the name was invalid
  std::map<std::pair<std::string, std::string>, std::size_t> interaction_pairs_;
};

}  // namespace

Scene parse_deck_string(const std::string& text, const std::string& path_for_messages,
                        const std::vector<std::string>& overrides) {
  toml::table root;
  try {
    root = toml::parse(text, std::string_view(path_for_messages));
  } catch (const toml::parse_error& e) {
    const auto& at = e.source().begin;
    throw InputError(
        fmt::format("{}:{}:{}: error: {}", path_for_messages, at.line, at.column, e.description()));
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
  char buffer[65536];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, stream)) > 0;)
    text.append(buffer, n);
  const bool failed = std::ferror(stream) != 0;
  const int read_errno = errno;
  std::fclose(stream);
  if (failed) {
    throw InputError(
        fmt::format("{}: error: cannot read deck: {}", path, std::strerror(read_errno)));
  }
  return parse_deck_string(text, path, overrides);
}

}  // namespace dem2d
