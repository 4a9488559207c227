// --set KEY=VALUE applied to the tree: the key path walked (creating tables on the way, an
// element of an array of tables selected by index or by name), the value read as TOML or else
// taken as a bare string, and the nodes made remembered with the option (Origins).
#include "io/deck_set.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <utility>
#include <vector>

#include "io/deck_schema.hpp"
#include "io/text.hpp"

namespace dem2d::deck {
namespace {

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
  for (const AlternativeKeys& group : kAlternativeKeys) {
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

}  // namespace

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
  drop_alternatives(*table, schema, last, origins);
  assign_override_value(*table, last, value);
  record_origin(*table->get(last), where, origins);
}

}  // namespace dem2d::deck
