// Resolved deck: a Scene written back as a deck with every default filled in, in TOML (which
// load_deck reads back to the same values) and in JSON (for run.json).
//
// The scene is first laid out once as an ordered tree of keys (DeckTable): each table's keys
// come from its description (deck_schema.hpp), in that order, each through its field and only
// where the description says the resolved deck has it; which tables there are is the code of
// scene_table(). The TOML and JSON writers only differ in punctuation. Numbers are written in
// their shortest form that reads back to the same double.
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "io/deck.hpp"
#include "io/deck_schema.hpp"
#include "io/text.hpp"

namespace dem2d {
namespace {

using deck::Value;

struct DeckTable;

// One key of a table: a value, a table [key], or an array of tables [[key]].
struct DeckEntry {
  enum class Kind { kValue, kTable, kTableArray };
  std::string key;
  Kind kind = Kind::kValue;
  Value value;
  std::vector<DeckTable> tables;  // one for kTable
};

struct DeckTable {
  std::vector<DeckEntry> entries;

  void value(std::string key, Value v) {
    entries.push_back({std::move(key), DeckEntry::Kind::kValue, std::move(v), {}});
  }
  void table(std::string key, DeckTable t) {
    entries.push_back({std::move(key), DeckEntry::Kind::kTable, {}, {std::move(t)}});
  }
  void table_array(std::string key, std::vector<DeckTable> ts) {
    entries.push_back({std::move(key), DeckEntry::Kind::kTableArray, {}, std::move(ts)});
  }
};

// The keys of one table that the resolved deck has, by its description: each key the
// contact model takes, that is written back, and that its `written_if` keeps.
template <class T>
DeckTable keys_table(const deck::Table<T>& spec, const T& item, ContactModelKind model) {
  DeckTable t;
  for (const deck::Key<T>& key : spec.keys) {
    if (key.field.load == nullptr || !deck::takes(key.models, model)) continue;
    if (key.written_if != nullptr && !key.written_if(item)) continue;
    if (std::optional<Value> value = key.field.load(item)) {
      t.value(std::string(key.name), std::move(*value));
    }
  }
  return t;
}

template <class T>
std::vector<DeckTable> keys_tables(const deck::Table<T>& spec, const std::vector<T>& items,
                                   ContactModelKind model) {
  std::vector<DeckTable> tables;
  for (const T& item : items) tables.push_back(keys_table(spec, item, model));
  return tables;
}

// The whole scene as the ordered tree of a deck, its tables in the order of kTopLevelKeys.
DeckTable scene_table(const Scene& scene) {
  const ContactModelKind model = scene.contact.model;
  DeckTable root = keys_table(deck::kTopLevel, scene, model);  // the title
  root.table("run", keys_table(deck::kRun, scene.run, model));
  root.table("contact", keys_table(deck::kContact, scene.contact, model));
  root.table_array("material", keys_tables(deck::kMaterial, scene.materials, model));
  root.table_array("interaction", keys_tables(deck::kInteraction, scene.interactions, model));
  if (scene.drum.present) {
    DeckTable drum = keys_table(deck::kDrum, scene.drum, model);
    if (!scene.drum.lifters.empty()) {
      drum.table_array("lifter", keys_tables(deck::kLifter, scene.drum.lifters, model));
    }
    root.table("drum", std::move(drum));
  }
  std::vector<DeckTable> fills = keys_tables(deck::kFill, scene.fills, model);
  for (const auto& f : scene.file_fills) fills.push_back(keys_table(deck::kFill, f, model));
  root.table_array("fill", std::move(fills));

  // The particles the file fills read are written as their files, not one by one.
  std::int64_t from_files = 0;
  for (const auto& f : scene.file_fills) from_files += f.count;
  const std::int64_t explicit_count =
      std::max<std::int64_t>(0, static_cast<std::int64_t>(scene.particles.size()) - from_files);
  std::vector<DeckTable> particles;
  for (std::int64_t i = 0; i < explicit_count; ++i) {
    particles.push_back(
        keys_table(deck::kParticle, scene.particles[static_cast<std::size_t>(i)], model));
  }
  root.table_array("particle", std::move(particles));
  root.table_array("wall", keys_tables(deck::kWall, scene.walls, model));
  if (scene.breakage.present)
    root.table("breakage", keys_table(deck::kBreakage, scene.breakage, model));
  if (scene.feed.present) root.table("feed", keys_table(deck::kFeed, scene.feed, model));
  if (scene.sieve.present) root.table("sieve", keys_table(deck::kSieve, scene.sieve, model));
  if (scene.shell.present) root.table("shell", keys_table(deck::kShell, scene.shell, model));
  root.table("output", keys_table(deck::kOutput, scene.output, model));
  return root;
}

// ---------------------------------------------------------------------------------------------
// Writers

// TOML: a table's values, then its sub-tables under headers ("prefix" is the dotted path).
void write_toml(const DeckTable& table, const std::string& prefix, std::string& out) {
  for (const DeckEntry& e : table.entries) {
    if (e.kind == DeckEntry::Kind::kValue) {
      out += fmt::format("{} = {}\n", e.key, deck::toml_text(e.value));
    }
  }
  for (const DeckEntry& e : table.entries) {
    const std::string name = prefix.empty() ? e.key : prefix + "." + e.key;
    if (e.kind == DeckEntry::Kind::kTable) {
      out += fmt::format("\n[{}]\n", name);
      write_toml(e.tables.front(), name, out);
    } else if (e.kind == DeckEntry::Kind::kTableArray) {
      for (const DeckTable& element : e.tables) {
        out += fmt::format("\n[[{}]]\n", name);
        write_toml(element, name, out);
      }
    }
  }
}

// JSON: an object per table, an array of objects per array of tables, in deck order.
void write_json(const DeckTable& table, int depth, std::string& out) {
  const std::string indent(static_cast<std::size_t>(2 * (depth + 1)), ' ');
  const std::string close_indent(static_cast<std::size_t>(2 * depth), ' ');
  out += "{";
  for (std::size_t i = 0; i < table.entries.size(); ++i) {
    const DeckEntry& e = table.entries[i];
    out += (i > 0 ? ",\n" : "\n") + indent + quoted_string(e.key) + ": ";
    if (e.kind == DeckEntry::Kind::kValue) {
      out += deck::json_text(e.value);
    } else if (e.kind == DeckEntry::Kind::kTable) {
      write_json(e.tables.front(), depth + 1, out);
    } else if (e.tables.empty()) {
      out += "[]";
    } else {
      out += "[";
      for (std::size_t j = 0; j < e.tables.size(); ++j) {
        out += (j > 0 ? ", " : "");
        write_json(e.tables[j], depth + 1, out);
      }
      out += "]";
    }
  }
  out += table.entries.empty() ? "}" : "\n" + close_indent + "}";
}

}  // namespace

std::string resolved_deck_toml(const Scene& scene) {
  std::string out = "# dem2d resolved deck: every key with the value the run used\n";
  write_toml(scene_table(scene), "", out);
  return out;
}

std::string resolved_deck_json(const Scene& scene) {
  std::string out;
  write_json(scene_table(scene), 0, out);
  return out;
}

}  // namespace dem2d
