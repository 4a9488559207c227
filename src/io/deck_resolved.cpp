// Resolved deck: a Scene written back as a deck with every default filled in, in TOML (which
// load_deck reads back to the same values) and in JSON (for run.json).
//
// The scene is first laid out once as an ordered tree of keys (DeckTable, in the order of
// docs/input.md); the TOML and JSON writers only differ in punctuation. Numbers are written
// in their shortest form that reads back to the same double.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "io/deck.hpp"
#include "io/deck_schema.hpp"
#include "io/text.hpp"

namespace dem2d {
namespace {

struct DeckTable;

// A value: number, integer, boolean, string, [x, y], or an array of strings.
using Strings = std::vector<std::string>;
using Scalar = std::variant<double, std::int64_t, bool, std::string, Vec2, Strings>;

// One key of a table: a value, a table [key], or an array of tables [[key]].
struct DeckEntry {
  enum class Kind { kValue, kTable, kTableArray };
  std::string key;
  Kind kind = Kind::kValue;
  Scalar value;
  std::vector<DeckTable> tables;  // one for kTable
};

struct DeckTable {
  std::vector<DeckEntry> entries;

  void value(std::string key, Scalar v) {
    entries.push_back({std::move(key), DeckEntry::Kind::kValue, std::move(v), {}});
  }
  void number(std::string key, double v) { value(std::move(key), v); }
  void integer(std::string key, std::int64_t v) { value(std::move(key), v); }
  void text(std::string key, std::string v) { value(std::move(key), std::move(v)); }
  void table(std::string key, DeckTable t) {
    entries.push_back({std::move(key), DeckEntry::Kind::kTable, {}, {std::move(t)}});
  }
  void table_array(std::string key, std::vector<DeckTable> ts) {
    entries.push_back({std::move(key), DeckEntry::Kind::kTableArray, {}, std::move(ts)});
  }
};

// Degrees for the deck such that deg * kRadiansPerDegree reproduces `radians` bit for bit
// (the reader's conversion). Several doubles near radians / kRadiansPerDegree may; the one
// with the shortest text is the one a person typed (15, not 14.999999999999998).
double degrees_for(double radians) {
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

DeckTable material_table(const MaterialSpec& m, ContactModelKind model) {
  DeckTable t;
  t.text("name", m.name);
  t.number("density", m.density);
  t.number("youngs_modulus", m.youngs_modulus);
  // Whichever of nu and G the reader turns back into exactly this pair: G = E / (2 (1 + nu))
  // when that reproduces G (always, when the deck gave nu), else G (nu = E / (2 G) - 1).
  if (m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio)) == m.shear_modulus) {
    t.number("poisson_ratio", m.poisson_ratio);
  } else {
    t.number("shear_modulus", m.shear_modulus);
  }
  if (model == ContactModelKind::kThesis) {
    t.number("damping_normal", m.damping_normal);
    t.number("damping_tangential", m.damping_tangential);
  } else {
    t.number("restitution", m.restitution);
  }
  t.number("sliding_friction", m.sliding_friction);
  t.number("rolling_friction", m.rolling_friction);
  if (model == ContactModelKind::kLinear && m.normal_stiffness > 0.0) {
    t.number("normal_stiffness", m.normal_stiffness);  // 0: derived by the core
  }
  return t;
}

DeckTable interaction_table(const InteractionSpec& spec) {
  DeckTable t;
  t.value("materials", Strings{spec.material_a, spec.material_b});
  const auto optional = [&](const char* key, const std::optional<double>& v) {
    if (v) t.number(key, *v);
  };
  optional("restitution", spec.restitution);
  optional("damping_normal", spec.damping_normal);
  optional("damping_tangential", spec.damping_tangential);
  optional("sliding_friction", spec.sliding_friction);
  optional("rolling_friction", spec.rolling_friction);
  return t;
}

DeckTable drum_table(const DrumSpec& drum) {
  DeckTable t;
  t.number("radius", drum.radius);
  t.value("center", drum.center);
  t.number("speed", drum.speed);  // rad/s, whatever the deck gave
  t.number("ramp_time", drum.ramp_time);
  t.integer("sides", drum.sides);
  t.number("angle", degrees_for(drum.angle));
  t.text("material", drum.material);
  std::vector<DeckTable> lifters;
  for (const LifterSpec& lifter : drum.lifters) {
    DeckTable l;
    l.integer("count", lifter.count);
    l.number("height", lifter.height);
    l.number("width", lifter.width);
    l.number("angle", degrees_for(lifter.angle));
    if (!lifter.material.empty()) l.text("material", lifter.material);  // "": the drum's
    lifters.push_back(std::move(l));
  }
  if (!lifters.empty()) t.table_array("lifter", std::move(lifters));
  return t;
}

DeckTable fill_table(const FillSpec& fill) {
  DeckTable t;
  if (!fill.material.empty()) t.text("material", fill.material);
  if (!fill.file.empty()) {
    t.text("file", fill.file);
    t.value("velocity", fill.velocity);
    return t;
  }
  if (fill.fill_fraction > 0.0) {
    t.number("fill_fraction", fill.fill_fraction);
  } else {
    t.integer("count", fill.count);
  }
  if (fill.radius_min == fill.radius_max) {
    t.number("radius", fill.radius_min);
  } else {
    t.number("radius_min", fill.radius_min);
    t.number("radius_max", fill.radius_max);
  }
  t.text("region", std::string(deck::choice_name(deck::kFillRegions, fill.region)));
  if (fill.region == FillRegion::kBox) {
    t.value("box_min", fill.box_min);
    t.value("box_max", fill.box_max);
  }
  t.value("velocity", fill.velocity);
  return t;
}

// The whole scene as the ordered tree of a deck.
DeckTable scene_table(const Scene& scene) {
  DeckTable root;
  root.text("title", scene.title);

  DeckTable run;
  const RunSpec& r = scene.run;
  run.number("duration", r.duration);
  if (r.dt_auto) {
    run.text("dt", "auto");
  } else {
    run.number("dt", r.dt);
  }
  run.text("integrator", std::string(deck::choice_name(deck::kIntegrators, r.integrator)));
  run.number("tolerance", r.tolerance);
  run.integer("max_passes", r.max_passes);
  run.integer("seed", static_cast<std::int64_t>(r.seed));
  run.value("gravity", r.gravity);
  if (r.skin >= 0.0) run.number("skin", r.skin);  // absent: the core chooses
  run.number("dt_safety", r.dt_safety);
  run.value("allow_unsafe_dt", r.allow_unsafe_dt);
  run.integer("sectors_per_rank", r.sectors_per_rank);
  run.number("repartition_threshold", r.repartition_threshold);
  root.table("run", std::move(run));

  DeckTable contact;
  const ContactSpec& c = scene.contact;
  contact.text("model", std::string(deck::choice_name(deck::kContactModels, c.model)));
  contact.text("rolling", std::string(deck::choice_name(deck::kRollingModels, c.rolling)));
  contact.number("rolling_damping", c.rolling_damping);
  root.table("contact", std::move(contact));

  std::vector<DeckTable> materials;
  for (const auto& m : scene.materials) materials.push_back(material_table(m, c.model));
  root.table_array("material", std::move(materials));
  std::vector<DeckTable> interactions;
  for (const auto& i : scene.interactions) interactions.push_back(interaction_table(i));
  root.table_array("interaction", std::move(interactions));
  if (scene.drum.present) root.table("drum", drum_table(scene.drum));

  std::vector<DeckTable> fills;
  for (const auto& f : scene.fills) fills.push_back(fill_table(f));
  for (const auto& f : scene.file_fills) fills.push_back(fill_table(f));
  root.table_array("fill", std::move(fills));

  // The particles the file fills read are written as their files, not one by one.
  std::int64_t from_files = 0;
  for (const auto& f : scene.file_fills) from_files += f.count;
  const std::int64_t explicit_count =
      std::max<std::int64_t>(0, static_cast<std::int64_t>(scene.particles.size()) - from_files);
  std::vector<DeckTable> particles;
  for (std::int64_t i = 0; i < explicit_count; ++i) {
    const ParticleSpec& p = scene.particles[static_cast<std::size_t>(i)];
    DeckTable t;
    t.text("material", p.material);
    t.number("radius", p.radius);
    t.value("position", p.position);
    t.value("velocity", p.velocity);
    t.number("spin", p.spin);
    particles.push_back(std::move(t));
  }
  root.table_array("particle", std::move(particles));

  std::vector<DeckTable> walls;
  for (const auto& w : scene.walls) {
    DeckTable t;
    t.value("from", w.from);
    t.value("to", w.to);
    t.text("material", w.material);
    t.value("velocity", w.velocity);
    walls.push_back(std::move(t));
  }
  root.table_array("wall", std::move(walls));

  DeckTable output;
  const OutputSpec& o = scene.output;
  output.text("directory", o.directory);
  output.number("series_interval", o.series_interval);
  output.number("snapshot_interval", o.snapshot_interval);
  output.number("checkpoint_interval", o.checkpoint_interval);
  output.number("progress_interval", o.progress_interval);
  root.table("output", std::move(output));
  return root;
}

// ---------------------------------------------------------------------------------------------
// Writers

enum class Syntax { kToml, kJson };

std::string number_text(double v, Syntax syntax) {
  return syntax == Syntax::kToml ? toml_number(v) : json_number(v);
}

std::string scalar_text(const Scalar& value, Syntax syntax) {
  struct Visitor {
    Syntax syntax;
    std::string operator()(double v) const { return number_text(v, syntax); }
    std::string operator()(std::int64_t v) const { return fmt::format("{}", v); }
    std::string operator()(bool v) const { return v ? "true" : "false"; }
    std::string operator()(const std::string& v) const { return quoted_string(v); }
    std::string operator()(Vec2 v) const {
      return fmt::format("[{}, {}]", number_text(v.x, syntax), number_text(v.y, syntax));
    }
    std::string operator()(const Strings& v) const {
      std::string out = "[";
      for (std::size_t i = 0; i < v.size(); ++i) out += (i > 0 ? ", " : "") + quoted_string(v[i]);
      return out + "]";
    }
  };
  return std::visit(Visitor{syntax}, value);
}

// TOML: a table's values, then its sub-tables under headers ("prefix" is the dotted path).
void write_toml(const DeckTable& table, const std::string& prefix, std::string& out) {
  for (const DeckEntry& e : table.entries) {
    if (e.kind == DeckEntry::Kind::kValue) {
      out += fmt::format("{} = {}\n", e.key, scalar_text(e.value, Syntax::kToml));
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
      out += scalar_text(e.value, Syntax::kJson);
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
