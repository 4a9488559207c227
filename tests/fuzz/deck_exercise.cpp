#include "deck_exercise.hpp"

#include <algorithm>
#include <stdexcept>

#include "core/base/errors.hpp"
#include "core/base/scene.hpp"
#include "core/setup/validate.hpp"
#include "core/shape/particles.hpp"
#include "core/step/time_scales.hpp"
#include "io/deck.hpp"
#include "io/particle_csv.hpp"

namespace dem2d::fuzz {
namespace {

// The next line of `text` (without its '\n'), removed from `text`.
std::string_view take_line(std::string_view& text) {
  const std::size_t newline = text.find('\n');
  const std::string_view line = text.substr(0, newline);
  text.remove_prefix(newline == std::string_view::npos ? text.size() : newline + 1);
  return line;
}

bool is_marker(std::string_view line, std::string_view marker) {
  if (line.ends_with('\r')) line.remove_suffix(1);
  return line == marker;
}

// A particle store holding the deck's own particles ([[particle]] and file fills) and, for
// each placed fill, one particle of its smallest radius at the drum's centre: the particles
// that set the time scales (per material, the smallest radius and the fastest particle),
// without placing the fills.
void add_particles(const Scene& scene, ParticleStore& store) {
  std::int64_t id = 0;
  for (const ParticleSpec& p : scene.particles) {
    const int material = find_material(scene, p.material);
    store.add(id++, material, p.radius, scene.materials[material].density, p.position, p.velocity,
              p.spin);
  }
  for (std::size_t f = 0; f < scene.fills.size(); ++f) {
    const FillSpec& fill = scene.fills[f];
    const int material = find_material(scene, fill.material);
    store.add(id++, material, fill.radius_min, scene.materials[material].density, scene.drum.center,
              fill.velocity, 0.0);
  }
}

// The resolved deck (as run.json holds it) must read back.
void check_resolved(const Scene& scene) {
  resolved_deck_json(scene);
  const std::string resolved = resolved_deck_toml(scene);
  try {
    parse_deck_string(resolved, std::string(kDeckPath));
  } catch (const InputError& e) {
    throw std::logic_error("the resolved deck does not read back:\n" + std::string(e.what()) +
                           "resolved deck:\n" + resolved);
  }
}

// What follows a successful read without MPI (see exercise_deck), as Simulation does it but
// with one particle per fill: the time scales, dt, then the checks of the first step.
void check_scene(const Scene& scene) {
  for (std::size_t f = 0; f < scene.fills.size(); ++f) expected_fill_count(scene, f);
  ParticleStore store;
  add_particles(scene, store);
  const TimeScales scales = time_scales(scene, store);
  const double dt = scene.run.dt_auto || scene.run.dt <= 0.0 ? scales.safe_dt : scene.run.dt;
  validate_start(scene, store, dt);
  check_resolved(scene);
}

}  // namespace

FuzzCase split_case(std::string_view data) {
  FuzzCase c;
  std::size_t deck_end = data.size();  // where the first marker line starts
  bool in_overrides = false;
  for (std::string_view rest = data; !rest.empty() && !c.csv;) {
    const std::size_t start = data.size() - rest.size();
    const std::string_view line = take_line(rest);
    const bool csv = is_marker(line, kCsvMarker);
    if (csv || is_marker(line, kSetMarker)) deck_end = std::min(deck_end, start);
    if (csv) {
      c.csv = std::string(rest);
    } else if (is_marker(line, kSetMarker)) {
      in_overrides = true;
    } else if (in_overrides) {
      c.overrides.emplace_back(line);
    }
  }
  c.deck = data.substr(0, deck_end);
  return c;
}

void exercise_deck(std::string_view data) {
  const FuzzCase c = split_case(data);
  if (c.csv) {
    const CsvPacking packing =
        read_particle_csv(*c.csv, "fuzz-deck/packing.csv", {"steel", "ore"}, {"steel", {}});
    if (packing.errors.size() > static_cast<std::size_t>(kMaxCsvErrors) + 1)
      throw std::logic_error("more CSV messages than kMaxCsvErrors + 1");
  }
  const Scene scene = parse_deck_string(c.deck, std::string(kDeckPath), c.overrides);
  check_scene(scene);
}

}  // namespace dem2d::fuzz
