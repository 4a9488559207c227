// Deck reader: TOML text -> --set overrides -> validation -> Scene (docs/input.md).
//
// One toml::table goes through three stages. The overrides are applied to the tree, and every
// node they make is remembered with the option's text (Origins), so that a message about it
// names the option (deck_set.cpp). Then a DeckParser reads every table in two passes. The
// per-key pass walks the table's description (deck_schema.hpp): a TableReader (deck_reader.hpp)
// checks each key's type, range and presence and reports unknown keys with the closest valid
// one; each accepted value goes into the Scene through the key's field. The rules between keys
// of the table follow as code (one of speed / speed_rpm / critical_fraction, ...), then the
// checks across tables (material references, particle sources, where the particles start:
// placement.cpp). Every message goes to one Diagnostics (deck_diagnostics.hpp); nothing throws
// before all of that has run, except a TOML syntax error (no tree to check).
#include "io/deck.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <numbers>
#include <optional>
#include <string_view>
#include <utility>

#include "core/base/errors.hpp"
#include "core/geometry/drum_geometry.hpp"
#include "io/deck_diagnostics.hpp"
#include "io/deck_reader.hpp"
#include "io/deck_schema.hpp"
#include "io/deck_set.hpp"
#include "io/particle_csv.hpp"
#include "io/placement.hpp"
#include "io/text.hpp"

namespace dem2d {
namespace {

namespace fs = std::filesystem;
using deck::apply_override;
using deck::as_value;
using deck::Bound;
using deck::Diagnostics;
using deck::expected_text;
using deck::FileRows;
using deck::Need;
using deck::Origins;
using deck::Placement;
using deck::TableReader;
using deck::Type;
using deck::Value;

// ---------------------------------------------------------------------------------------------
// Files

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

// A material's name holds no '.' (--set material.NAME.KEY names it), no ',' or '=' (the
// snapshots list the materials as "0=steel,1=ore") and no control character (a line of a
// message or of a CSV file).
bool valid_material_name(std::string_view name) {
  return !name.empty() && std::none_of(name.begin(), name.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return c == '.' || c == ',' || c == '=' || u < 0x20 || u == 0x7F;
  });
}

// A key that the keys around it make required (a fill's material, unless it reads a file).
template <class T>
void require(const TableReader& r, const deck::Table<T>& spec, std::string_view name) {
  if (r.has(name)) return;
  const deck::Key<T>* key = deck::find_key(spec.keys, name);
  r.missing(name, expected_text(key->type, key->range));
}

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
    if (const auto* t = root.table("shell")) read_shell(*t);
    if (const auto* t = root.table("output")) read_output(*t);
    check_ore(root_);
    check_shapes(root_);

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
      case Type::kNumberList:
        return as_value(r.numbers(key.name, key.range, key.need));
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
      if (!valid_material_name(m.name)) {
        r.invalid("name",
                  "must be a non-empty name without '.', ',', '=' or control characters "
                  "(letters, digits, spaces and other punctuation are allowed)");
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
    const std::size_t errors_before = diag_.messages().size();
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
    if (radius && diag_.messages().size() == errors_before) check_lifter_spacing(lifters);
  }

  // The bars of each [[drum.lifter]] stand apart from each other and from the other sets' bars.
  void check_lifter_spacing(const std::vector<const toml::table*>& tables) {
    const DrumGeometry drum(scene_.drum);
    for (std::size_t l = 0; l < tables.size(); ++l) {
      const LifterSpec& lifter = scene_.drum.lifters[l];
      // The top face's corners inside the shell: half a width across, top from the centre.
      const double top = drum.inner_radius() - lifter.height;
      const double widest =
          2.0 * std::sqrt(std::max(drum.radius() * drum.radius() - top * top, 0.0));
      if (!(lifter.width < widest)) {
        TableReader(diag_, *tables[l], deck::kLifter, l)
            .invalid("width", fmt::format("must be < {:.3g} m: wider, the corners of a bar's top "
                                          "face ({:g} m from the centre) lie outside the shell "
                                          "(drum.radius = {:g})",
                                          widest, top, drum.radius()));
        return;
      }
      const int fit = drum.bars_that_fit(l);
      if (lifter.count <= fit) continue;
      TableReader(diag_, *tables[l], deck::kLifter, l)
          .invalid(
              "count",
              fmt::format("the {} bars of width {:g} m overlap their neighbours: {} x {:g} m "
                          "= {:.3g} m of bars around the circle of their top faces, {:.3g} m "
                          "long (radius {:.3g} m); at most {} bars of this width fit "
                          "there apart (or, for {} bars, a width below {:.3g} m)",
                          lifter.count, lifter.width, lifter.count, lifter.width,
                          lifter.count * lifter.width, 2.0 * std::numbers::pi * top, top, fit,
                          lifter.count, 2.0 * top * std::tan(std::numbers::pi / lifter.count)));
      return;
    }
    if (const auto pair = drum.overlapping_sets()) {
      const DrumGeometry::Bar& a = drum.bars()[pair->first];
      const DrumGeometry::Bar& b = drum.bars()[pair->second];
      const TableReader r(diag_, *tables[b.lifter], deck::kLifter, b.lifter);
      const std::string message = fmt::format(
          "bar {} of drum.lifter[{}] overlaps bar {} of drum.lifter[{}]; give the "
          "sets angles that keep their bars apart",
          b.index, b.lifter, a.index, a.lifter);
      r.has("angle") ? r.invalid("angle", message) : r.error(r.path() + ": " + message);
    }
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
    const Accepted accepted = read_keys(r, deck::kParticle, p);
    p.source_line = r.line();
    read_particle_shape(r, accepted, p);
    scene_.particles.push_back(std::move(p));
  }

  // A disc takes radius; a superellipse semi_axes = [a, b] (and exponent, angle) instead.
  static void read_particle_shape(const TableReader& r, const Accepted& accepted, ParticleSpec& p) {
    if (r.has("shape") && !accepted.has("shape")) return;  // reported
    if (p.shape == ParticleShape::kDisc) {
      reject_shape_keys(r, {"semi_axes", "exponent", "angle"});
      require(r, deck::kParticle, "radius");
      return;
    }
    if (r.has("radius"))
      r.invalid("radius",
                "not used by shape = \"superellipse\" (semi_axes = [a, b] give its size)");
    require(r, deck::kParticle, "semi_axes");
    if (const auto ab = accepted.get<Vec2>("semi_axes");
        ab && !(ab->x >= deck::kMinRadius && ab->y >= deck::kMinRadius)) {
      r.invalid("semi_axes", fmt::format("each semi-axis must be >= {:g} m", deck::kMinRadius));
      p.semi_a = p.semi_b = 0.0;
    }
  }

  // Keys a disc does not take.
  static void reject_shape_keys(const TableReader& r,
                                std::initializer_list<std::string_view> keys) {
    for (const std::string_view key : keys)
      if (r.has(key))
        r.invalid(key,
                  "used only by shape = \"superellipse\" (the shape is \"disc\", the default)");
  }

  void read_fill(const toml::table& table, std::size_t index) {
    const TableReader r(diag_, table, deck::kFill, index);
    FillSpec fill;
    fill.source_line = r.line();
    fill.index = static_cast<int>(index);
    const Accepted accepted = read_keys(r, deck::kFill, fill);
    std::vector<std::string_view> sources;
    for (const std::string_view key : {"count", "fill_fraction", "bed_filling", "file"}) {
      if (r.has(key)) sources.push_back(key);
    }
    if (sources.size() != 1) {
      r.error(
          sources.empty()
              ? fmt::format("{} needs one of count, fill_fraction, bed_filling and file", r.path())
              : fmt::format("{}: give only one of count, fill_fraction, bed_filling and "
                            "file (found {})",
                            r.path(), and_list(sources)));
    }
    if (fill.shape == ParticleShape::kDisc) reject_shape_keys(r, {"aspect", "exponent"});
    if (sources.size() == 1 && sources[0] == "file") {
      for (const std::string_view key :
           {"radius", "radius_min", "radius_max", "size_distribution", "d50", "sigma",
            "geometric_sd", "sizes", "mass_fractions", "region", "box_min", "box_max", "mix",
            "shape", "aspect", "exponent"}) {
        if (r.has(key))
          r.invalid(key, "not used by a fill from a file (the file gives each particle)");
      }
      if (const auto file = accepted.get<std::string>("file")) read_fill_file(r, *file, fill);
      previous_fill_ = FillSpec{};
      previous_fill_->file = "(file)";
      return;
    }
    require(r, deck::kFill, "material");  // a file may name each row's material instead
    for (const std::string_view key : {"fill_fraction", "bed_filling"}) {
      if (accepted.has(key) && !scene_.drum.present)
        r.invalid(key, "needs a [drum] (it is a fraction of the drum's area)");
    }
    read_fill_sizes(r, accepted, fill);
    read_fill_region(r, accepted, fill);
    read_fill_mix(r, fill);
    previous_fill_ = fill;
    scene_.fills.push_back(std::move(fill));
  }

  // The size keys each law takes; any other is an error naming the law.
  static void reject_other_size_keys(const TableReader& r, const FillSpec& fill) {
    static constexpr std::string_view kKeys[] = {"radius", "radius_min",    "radius_max",
                                                 "d50",    "sigma",         "geometric_sd",
                                                 "sizes",  "mass_fractions"};
    std::vector<std::string_view> takes;
    switch (fill.size_distribution) {
      case SizeDistribution::kUniform:
        takes = {"radius", "radius_min", "radius_max"};
        break;
      case SizeDistribution::kNormal:
        takes = {"d50", "sigma", "radius_min", "radius_max"};
        break;
      case SizeDistribution::kLognormal:
        takes = {"d50", "geometric_sd", "radius_min", "radius_max"};
        break;
      case SizeDistribution::kTable:
        takes = {"sizes", "mass_fractions"};
        break;
    }
    const std::string law(deck::choice_name(deck::kSizeDistributions, fill.size_distribution));
    const std::string which = fill.size_distribution == SizeDistribution::kUniform
                                  ? "radius, or radius_min and radius_max"
                                  : and_list(takes);
    for (const std::string_view key : kKeys) {
      if (r.has(key) && std::find(takes.begin(), takes.end(), key) == takes.end())
        r.invalid(key, fmt::format("not used by size_distribution = \"{}\"{}, which takes {}", law,
                                   r.has("size_distribution") ? "" : " (the default)", which));
    }
  }

  // The fill's sizes by its law: radius or a radius range, a normal or lognormal law within
  // a radius range, or a table of sizes and mass fractions.
  static void read_fill_sizes(const TableReader& r, const Accepted& accepted, FillSpec& fill) {
    if (r.has("size_distribution") && !accepted.has("size_distribution")) return;  // reported
    reject_other_size_keys(r, fill);
    switch (fill.size_distribution) {
      case SizeDistribution::kUniform:
        read_fill_radii(r, accepted);
        return;
      case SizeDistribution::kNormal:
      case SizeDistribution::kLognormal:
        read_fill_law(r, accepted, fill);
        return;
      case SizeDistribution::kTable:
        read_fill_table(r, accepted, fill);
        return;
    }
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

  // "normal" and "lognormal": d50 and the spread, truncated to [2 radius_min, 2 radius_max].
  static void read_fill_law(const TableReader& r, const Accepted& accepted, const FillSpec& fill) {
    const bool normal = fill.size_distribution == SizeDistribution::kNormal;
    for (const std::string_view key :
         {std::string_view("d50"), normal ? std::string_view("sigma") : "geometric_sd",
          std::string_view("radius_min"), std::string_view("radius_max")})
      require(r, deck::kFill, key);
    const auto lo = accepted.get<double>("radius_min");
    const auto hi = accepted.get<double>("radius_max");
    if (!lo || !hi) return;
    if (*lo >= *hi) {
      r.invalid("radius_min",
                fmt::format("must be < radius_max = {} (the truncation of the {} law)",
                            r.shown("radius_max"), normal ? "normal" : "lognormal"));
      return;
    }
    const auto d50 = accepted.get<double>("d50");
    if (d50 && (*d50 < 2.0 * *lo || *d50 > 2.0 * *hi)) {
      r.invalid("d50", fmt::format("must lie within [2 radius_min, 2 radius_max] = [{:g}, {:g}] "
                                   "m (a diameter, within the truncation)",
                                   2.0 * *lo, 2.0 * *hi));
    }
  }

  // "table": diameters in increasing order, one mass fraction each, summing to 1.
  static void read_fill_table(const TableReader& r, const Accepted& accepted, FillSpec& fill) {
    require(r, deck::kFill, "sizes");
    require(r, deck::kFill, "mass_fractions");
    const auto sizes = accepted.get<deck::Numbers>("sizes");
    const auto fractions = accepted.get<deck::Numbers>("mass_fractions");
    if (sizes && !std::is_sorted(sizes->begin(), sizes->end(), std::less_equal<>())) {
      r.invalid("sizes", "must be in increasing order, each size once (diameters, m)");
    }
    if (sizes) {
      fill.radius_min = 0.5 * sizes->front();
      fill.radius_max = 0.5 * sizes->back();
    }
    if (!fractions) return;
    if (sizes && fractions->size() != sizes->size()) {
      r.invalid("mass_fractions", fmt::format("{} values for {} sizes; give one per size",
                                              fractions->size(), sizes->size()));
      return;
    }
    double sum = 0.0;
    for (const double w : *fractions) sum += w;
    if (std::abs(sum - 1.0) > 1e-9) {
      r.invalid("mass_fractions", fmt::format("sum to {:.12g}; must sum to 1 (within 1e-9)", sum));
    }
  }

  // mix = true: placed with the fill before it, which must be placed (not read from a file)
  // in the same region (the same box).
  void read_fill_mix(const TableReader& r, const FillSpec& fill) const {
    if (!fill.mix) return;
    const std::string before = fmt::format("fill[{}]", fill.index - 1);
    if (!previous_fill_) {
      r.invalid("mix", "the first [[fill]] has no fill before it to mix with");
    } else if (!previous_fill_->file.empty()) {
      r.invalid("mix", fmt::format("{} reads a file; only placed fills mix", before));
    } else if (previous_fill_->region != fill.region ||
               (fill.region == FillRegion::kBox && (previous_fill_->box_min != fill.box_min ||
                                                    previous_fill_->box_max != fill.box_max))) {
      r.invalid("mix", fmt::format("{} is placed in another region; mixed fills share their "
                                   "region (and box)",
                                   before));
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
    // The keys of one model or fragment law are errors under the other (rather than unused).
    const auto only = [&](std::string_view key, bool used, std::string_view by) {
      if (r.has(key) && !used) r.invalid(key, fmt::format("used only with {}", by));
    };
    const bool vp = b.model == BreakageModel::kVogelPeukert;
    for (const char* key : {"minimum_energy", "strength"}) only(key, !vp, "model = \"thesis\"");
    for (const char* key : {"f_mat", "xw_min"}) only(key, vp, "model = \"vogel-peukert\"");
    const bool t10 = b.fragments == FragmentLaw::kT10;
    for (const char* key : {"fragments_mean", "fragments_sd", "fragments_min", "fragments_max"})
      only(key, !t10, "fragments = \"equal\"");
    for (const char* key : {"t10_a", "t10_b", "fines_diameter"})
      only(key, t10, "fragments = \"t10\"");
    if (vp && !r.has("f_mat")) r.missing("f_mat", "model = \"vogel-peukert\", in kg/(J m)");
    if (t10) {
      if (!r.has("t10_a")) r.missing("t10_a", "fragments = \"t10\", in %");
      if (!r.has("t10_b")) r.missing("t10_b", "fragments = \"t10\", in t/kWh");
      if (!r.has("fines_diameter")) r.missing("fines_diameter", "fragments = \"t10\", in m");
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
    const DrumGeometry drum(d);
    const double clearance = drum.shell_clearance(f.point);
    if (clearance < f.radius_max) {
      r.invalid("point",
                fmt::format("a fed particle of radius_max {:g} m {} the drum (radius {:g} "
                            "m about [{:g}, {:g}]); give a point at least radius_max "
                            "inside the shell",
                            f.radius_max,
                            clearance <= -f.radius_max ? "lies outside" : "straddles the shell of",
                            d.radius, d.center.x, d.center.y));
    } else if (const auto bar = drum.bar_overlap(f.point, f.radius_max)) {
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
    const auto only = [&](std::string_view key, DischargeType type, std::string_view word) {
      if (r.has(key) && s.type != type)
        r.invalid(key, fmt::format("used only with type = \"{}\"", word));
    };
    only("box_min", DischargeType::kBox, "box");
    only("box_max", DischargeType::kBox, "box");
    only("grate_width", DischargeType::kGrate, "grate");
    only("holdup", DischargeType::kOverflow, "overflow");
    if (s.type == DischargeType::kBox &&
        !(s.box_max.x > s.box_min.x && s.box_max.y > s.box_min.y)) {
      r.invalid(accepted.has("box_max") ? "box_max" : "box_min",
                fmt::format("the zone must be above and right of box_min = [{}, {}]", s.box_min.x,
                            s.box_min.y));
    }
    if (s.type == DischargeType::kGrate) {
      if (!r.has("grate_width")) {
        r.missing("grate_width", "type = \"grate\", the ring's radial width in m");
      } else if (!scene_.drum.present) {
        r.invalid("type", "a grate needs a [drum] (it lies inside the shell)");
      } else if (s.grate_width >= scene_.drum.radius) {
        r.invalid("grate_width",
                  fmt::format("must be below the drum radius {:g} m", scene_.drum.radius));
      }
    }
    if (s.type == DischargeType::kOverflow && !r.has("holdup"))
      r.missing("holdup", "type = \"overflow\", the ore hold-up in kg");
  }

  // The shell needs a round drum (the ring is meshed about its circle) whose radius its wall and
  // elements fit.
  void read_shell(const toml::table& table) {
    const TableReader r(diag_, table, deck::kShell);
    ShellSpec& s = scene_.shell;
    s.present = true;
    read_keys(r, deck::kShell, s);
    const DrumSpec& d = scene_.drum;
    if (!d.present) {
      r.error("a [shell] needs a [drum]: it is the drum's wall");
    } else if (d.sides != 0) {
      r.error(fmt::format("a [shell] needs a round drum (drum.sides = 0); the drum is a {}-gon",
                          d.sides));
    } else if (d.lifters.empty()) {
      r.error("a [shell] reports per lifter bar (lifters.csv): the drum needs [[drum.lifter]]");
    } else if (r.has("thickness") && s.thickness >= 0.5 * d.radius) {
      r.invalid("thickness", fmt::format("must be below half the drum radius {:g} m", d.radius));
    } else if (s.element_size && (*s.element_size > 0.25 * d.radius ||
                                  2.0 * std::numbers::pi * d.radius / *s.element_size > 20000.0)) {
      r.invalid("element_size",
                fmt::format("must lie between {:g} m (20 000 elements around the ring) and a "
                            "quarter of the drum radius, {:g} m",
                            2.0 * std::numbers::pi * d.radius / 20000.0, 0.25 * d.radius));
    }
  }

  // The rules between the ore tables, each message naming the keys on both sides:
  //   - a particle that cannot break must be able to leave: 2 minimum_radius >= the aperture
  //     (else the ore between them neither breaks nor leaves);
  //   - a feed point inside the discharge zone is refused (it would leave at once).
  // Superellipses run with the Hertz-Mindlin law and the Verlet integrator only.
  void check_shapes(const toml::table& root) {
    if (!diag_.messages().empty() || !has_shaped_particles(scene_)) return;
    std::string shape_key;
    for (std::size_t i = 0; i < scene_.particles.size() && shape_key.empty(); ++i)
      if (scene_.particles[i].shaped()) shape_key = fmt::format("particle[{}].shape", i);
    for (std::size_t i = 0; i < scene_.fills.size() && shape_key.empty(); ++i)
      if (scene_.fills[i].shape == ParticleShape::kSuperellipse)
        shape_key = fmt::format("fill[{}].shape", scene_.fills[i].index);
    const toml::node* shape = root.at_path(shape_key).node();
    const std::string at = shape != nullptr ? diag_.where(*shape) : shape_key;
    const auto refuse = [&](const char* path, std::string_view value, std::string_view allowed) {
      const toml::node* node = root.at_path(path).node();
      diag_.error_in(node != nullptr ? diag_.where(*node) : std::string(diag_.where(root)),
                     fmt::format("{} = \"{}\"{}: superellipses ({} = \"superellipse\", {}) run "
                                 "with {} only",
                                 path, value, node != nullptr ? "" : " (the default)", shape_key,
                                 at, allowed));
    };
    if (scene_.contact.model != ContactModelKind::kHertzMindlin)
      refuse("contact.model", deck::choice_name(deck::kContactModels, scene_.contact.model),
             "contact.model = \"hertz-mindlin\"");
    if (scene_.run.integrator != IntegratorKind::kVerlet)
      refuse("run.integrator", deck::choice_name(deck::kIntegrators, scene_.run.integrator),
             "run.integrator = \"verlet\"");
  }

  void check_ore(const toml::table& root) {
    const BreakageSpec& b = scene_.breakage;
    const SieveSpec& s = scene_.sieve;
    if (!diag_.messages().empty()) return;
    const auto where = [&](const char* path) {
      const toml::node* node = root.at_path(path).node();
      return node != nullptr ? diag_.where(*node) : std::string("the default");
    };
    if (b.present && s.present && b.material == s.material && 2.0 * b.minimum_radius < s.aperture) {
      diag_.error_in(
          where("breakage.minimum_radius"),
          fmt::format(
              "breakage.minimum_radius = {:g} m: particles narrower than 2 x {:g} = {:g} m do "
              "not break, but only those narrower than sieve.aperture = {:g} m ({}) leave: the ore "
              "between would stay in the mill for ever; give minimum_radius >= aperture / 2 = {:g} "
              "m (the aperture is a diameter)",
              b.minimum_radius, b.minimum_radius, 2.0 * b.minimum_radius, s.aperture,
              where("sieve.aperture"), 0.5 * s.aperture));
    }
    const FeedSpec& f = scene_.feed;
    if (!(f.present && f.has_point && s.present)) return;
    if (s.type == DischargeType::kBox && f.point.x >= s.box_min.x && f.point.x <= s.box_max.x &&
        f.point.y >= s.box_min.y && f.point.y <= s.box_max.y) {
      diag_.error_in(
          where("feed.point"),
          fmt::format(
              "feed.point = [{:g}, {:g}] lies in the sieve's box [{:g}, {:g}] to [{:g}, {:g}] "
              "({}): fed ore narrower than the aperture would leave at once; give a point outside "
              "the box",
              f.point.x, f.point.y, s.box_min.x, s.box_min.y, s.box_max.x, s.box_max.y,
              where("sieve.box_min")));
    } else if (s.type == DischargeType::kGrate && scene_.drum.present &&
               norm(f.point - scene_.drum.center) > scene_.drum.radius - s.grate_width) {
      diag_.error_in(
          where("feed.point"),
          fmt::format(
              "feed.point = [{:g}, {:g}] lies in the grate ring (the last sieve.grate_width = "
              "{:g} m inside the shell, {}): fed ore narrower than the aperture would leave at "
              "once; give a point at most {:g} m from the drum centre",
              f.point.x, f.point.y, s.grate_width, where("sieve.grate_width"),
              scene_.drum.radius - s.grate_width));
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
  std::optional<FillSpec> previous_fill_;    // the [[fill]] read last (a file fill: its file)
  std::map<std::pair<std::string, std::string>, std::size_t> interaction_pairs_;
  std::vector<FileRows> file_rows_;  // the particles each [[fill]] file added, in order
};

// Where the deck gave the values that the checks after reading may refuse (Scene::where):
// the count and velocities of what the core places, the duration, the drum's speed.
void record_where(const toml::table& root, const Diagnostics& diag, Scene& scene) {
  const auto put = [&](const std::string& key, const toml::node* node) {
    if (node != nullptr) scene.where[key] = diag.where(*node);
  };
  for (const char* key :
       {"run.duration", "run.dt", "drum.speed", "drum.speed_rpm", "drum.critical_fraction",
        "feed.velocity", "sieve.type", "output.directory", "output.series_interval",
        "output.snapshot_interval", "output.checkpoint_interval"}) {
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
  each("fill", {"count", "fill_fraction", "bed_filling", "radius", "radius_max", "sizes",
                "velocity", "file"});
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
