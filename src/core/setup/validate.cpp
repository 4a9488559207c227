#include "core/setup/validate.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "core/base/errors.hpp"
#include "core/contact/contact_engine.hpp"
#include "core/geometry/drum_geometry.hpp"
#include "core/setup/size_law.hpp"
#include "core/step/integrators.hpp"

namespace dem2d {

namespace {

constexpr double kGiB = 1024.0 * 1024.0 * 1024.0;
constexpr int kMaxRowMessages = 20;  // per CSV file, as the reader's own (kMaxCsvErrors)

// A number as %g writes it with `digits` significant digits: "1e+06", "0.25".
std::string num(double x, int digits = 6) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", digits, x);
  return buffer;
}

std::string vec(Vec2 v) { return "[" + num(v.x) + ", " + num(v.y) + "]"; }

// Where the deck set `key` (Scene::where), else the deck as a whole.
std::string where(const Scene& scene, const std::string& key) {
  const auto it = scene.where.find(key);
  return it != scene.where.end() ? it->second : scene.deck_path;
}

std::string error_at(const Scene& scene, const std::string& key, const std::string& message) {
  return where(scene, key) + ": error: " + key + message;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Memory

double expected_fill_count(const Scene& scene, std::size_t fill) {
  const FillSpec& s = scene.fills[fill];
  if (s.count > 0) return static_cast<double>(s.count);
  const double mean_area = mean_particle_area(s);
  return mean_area > 0.0 ? std::ceil(fill_target_area(scene, s) / mean_area) : 0.0;
}

double fill_lattice_sites(const Scene& scene, std::size_t fill) {
  const FillSpec& s = scene.fills[fill];
  const double spacing = 2.1 * placement_radius_max(s);
  if (!(spacing > 0.0)) return 0.0;
  Vec2 extent = s.box_max - s.box_min;
  double kept = 1.0;  // the share of the bounding box's sites the region keeps
  if (s.region != FillRegion::kBox) {
    const double d = 2.0 * DrumGeometry(scene.drum).inner_radius();
    extent = {d, d};
    kept = std::numbers::pi / 4.0;
  }
  const double columns = std::max(extent.x, 0.0) / spacing + 1.0;
  const double rows = std::max(extent.y, 0.0) / (spacing * std::sqrt(3.0) / 2.0) + 1.0;
  return kept * columns * rows;
}

double particle_memory_bytes(const Scene& scene, double particles) {
  ParticleStore store;
  if (scene.breakage.present) store.enable_damage();
  if (has_shaped_particles(scene)) store.enable_shape();
  // The contact histories' width: the slots the scene's contact model declares.
  Scene models;
  models.materials = scene.materials;
  models.interactions = scene.interactions;
  models.contact = active_contact(scene);
  models.run.integrator = scene.run.integrator;
  const double width = static_cast<double>(ContactEngine(models).history_slots().size());
  // A pair: local indices i, j (4 bytes each), ids (8 each), history and trial slots (8 each).
  const double pair = 2.0 * 4.0 + 2.0 * 8.0 + 2.0 * 8.0 * width;
  const double per_particle =
      2.0 * static_cast<double>(store.bytes_per_particle()) + kPairsPerParticle * pair;
  return 2.0 * particles * per_particle;
}

double lattice_memory_bytes(double sites) { return 2.5 * 24.0 * sites; }

double physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page = ::sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return 0.0;
  return static_cast<double>(pages) * static_cast<double>(page);
}

namespace {

// The key that sets how many particles fill f places (count, fill_fraction or bed_filling),
// and its value.
std::string count_key(const Scene& scene, std::size_t f) {
  const FillSpec& s = scene.fills[f];
  const std::string fill = "fill[" + std::to_string(s.index) + "]";
  if (s.count > 0) return fill + ".count";
  return s.bed_filling > 0.0 ? fill + ".bed_filling" : fill + ".fill_fraction";
}

std::string count_text(const FillSpec& s) {
  if (s.count > 0) return std::to_string(s.count);
  return num(s.bed_filling > 0.0 ? s.bed_filling : s.fill_fraction);
}

// The fill's radius key: radius, radius_max of a range, or a table's sizes.
std::string radius_key(const Scene& scene, const FillSpec& s) {
  const std::string fill = "fill[" + std::to_string(s.index) + "]";
  if (scene.where.contains(fill + ".sizes")) return fill + ".sizes";  // a table: its largest
  return scene.where.contains(fill + ".radius_max") ? fill + ".radius_max" : fill + ".radius";
}

}  // namespace

void check_memory(const Scene& scene, double available) {
  if (!(available > 0.0)) return;
  double particles = static_cast<double>(scene.particles.size());
  std::size_t largest = 0;
  for (std::size_t f = 0; f < scene.fills.size(); ++f) {
    particles += expected_fill_count(scene, f);
    if (expected_fill_count(scene, f) > expected_fill_count(scene, largest)) largest = f;
  }
  const double bytes = particle_memory_bytes(scene, particles);
  const std::string machine = ", more than this machine's " + num(available / kGiB, 3) + " GiB";
  if (bytes > available) {
    const std::string need = "the particles at the start (" + num(particles, 3) +
                             " in all, about " + num(bytes / particles, 3) +
                             " bytes each with their neighbour lists) would need about " +
                             num(bytes / kGiB, 3) + " GiB of memory" + machine;
    if (scene.fills.empty()) throw InputError(scene.deck_path + ": error: " + need);
    const FillSpec& s = scene.fills[largest];
    const std::string many = s.count > 0 ? std::string()
                                         : "about " + num(expected_fill_count(scene, largest), 3) +
                                               " particles of radius " + num(s.radius_max) + " m; ";
    throw InputError(error_at(
        scene, count_key(scene, largest),
        " = " + count_text(s) + ": " + many + need + "; place fewer particles or larger ones"));
  }
  std::vector<std::string> errors;
  for (std::size_t f = 0; f < scene.fills.size(); ++f) {
    const double sites = fill_lattice_sites(scene, f);
    const double lattice = lattice_memory_bytes(sites);
    if (bytes + lattice <= available) continue;
    const FillSpec& s = scene.fills[f];
    errors.push_back(error_at(
        scene, radius_key(scene, s),
        " = " + num(s.radius_max) + ": placing the fill lays a lattice of " + num(sites, 3) +
            " sites (spacing 2.1 times the radius) over its region, which would need about " +
            num(lattice / kGiB, 3) + " GiB of memory" + machine +
            "; use larger particles or a smaller region"));
  }
  if (!errors.empty()) throw InputError(errors);
}

// ---------------------------------------------------------------------------------------------
// The first step

namespace {

// How far things move in one step of dt, and how the messages say it.
class StepMotion {
 public:
  StepMotion(const Scene& scene, double dt) : scene_(scene), dt_(dt) {}

  // "; dt = 8.5e-07 s (dt = "auto")"
  std::string dt_text() const {
    return "dt = " + num(dt_, 3) + " s" + (scene_.run.dt_auto ? " (dt = \"auto\")" : " (run.dt)");
  }
  // A body moving at `speed` past radius r: "" when it moves at most kMaxStepMotion r in a step,
  // else what is wrong ("the particle would move 17 times its radius (0.05 m) in ...").
  std::string too_far(const std::string& body, const std::string& radius_of, double speed, double r,
                      const std::string& when = "the first step") const {
    const double motion = dt_ * speed / r;
    if (!(r > 0.0) || !(motion > kMaxStepMotion)) return "";
    return body + " would move " + num(motion, 3) + " times " + radius_of + " (" + num(r) +
           " m) in " + when + " at " + dt_text() + "; at most " + num(kMaxStepMotion) +
           " of a radius per step is allowed (here a speed up to " +
           num(kMaxStepMotion * r / dt_, 3) + " m/s), or bodies could pass through each other";
  }
  // A spin turning the surface of a particle: "" when it moves at most kMaxStepMotion r.
  std::string too_fast(double spin) const {
    const double motion = dt_ * std::abs(spin);
    if (!(motion > kMaxStepMotion)) return "";
    return "the particle's surface would move " + num(motion, 3) +
           " times its radius in the first step at " + dt_text() + "; at most " +
           num(kMaxStepMotion) + " of a radius per step is allowed (here a spin up to " +
           num(kMaxStepMotion / dt_, 3) + " rad/s)";
  }

 private:
  const Scene& scene_;
  double dt_;
};

// Adds "WHERE: error: KEY = VALUE UNIT: PROBLEM" when there is a problem.
void add(std::vector<std::string>& errors, const std::string& where, const std::string& key,
         const std::string& value, const std::string& problem) {
  if (!problem.empty())
    errors.push_back(where + ": error: " + key + " = " + value + ": " + problem);
}

// The [[particle]] tables: the first particles, one per table.
void check_tables(const Scene& s, std::size_t tables, const StepMotion& step,
                  std::vector<std::string>& errors) {
  for (std::size_t i = 0; i < tables; ++i) {
    const ParticleSpec& p = s.particles[i];
    const std::string key = "particle[" + std::to_string(i) + "]";
    add(errors, where(s, key + ".velocity"), key + ".velocity", vec(p.velocity) + " m/s",
        step.too_far("the particle", "its radius", norm(p.velocity), p.radius));
    add(errors, where(s, key + ".spin"), key + ".spin", num(p.spin) + " rad/s",
        step.too_fast(p.spin));
  }
}

// The rows of one fill from a file, particles [first, first + count): a row's own velocity
// and spin at its line; the fill's velocity (rows without vx, vy) at the fill's key.
void check_rows(const Scene& s, const FillSpec& fill, std::size_t first, const StepMotion& step,
                std::vector<std::string>& errors) {
  const std::string key = "fill[" + std::to_string(fill.index) + "]";
  const auto csv = s.where.find(key + ".csv");
  const std::string file = csv != s.where.end() ? csv->second : fill.file;
  std::vector<std::string> rows;
  double r_default = HUGE_VAL;  // the smallest radius among rows that take the fill's velocity
  const std::size_t end =
      std::min(first + static_cast<std::size_t>(fill.count), s.particles.size());
  for (std::size_t k = first; k < end; ++k) {
    const ParticleSpec& p = s.particles[k];
    const bool own = p.velocity != fill.velocity;  // else the fill's, checked below
    if (!own) r_default = std::min(r_default, p.radius);
    const std::string moves =
        own ? step.too_far("the particle", "its radius", norm(p.velocity), p.radius) : "";
    const std::string turns = step.too_fast(p.spin);
    if (moves.empty() && turns.empty()) continue;
    const std::string at = file + ":" + std::to_string(p.source_line);
    add(rows, at, key + ".file row: velocity", vec(p.velocity) + " m/s", moves);
    add(rows, at, key + ".file row: spin", num(p.spin) + " rad/s", turns);
  }
  const std::size_t shown = std::min<std::size_t>(rows.size(), kMaxRowMessages);
  errors.insert(errors.end(), rows.begin(), rows.begin() + static_cast<long>(shown));
  if (rows.size() > shown) {
    errors.push_back(file + ": error: " + std::to_string(rows.size() - shown) +
                     " more rows of this file move too far in the first step");
  }
  if (r_default < HUGE_VAL) {
    add(errors, where(s, key + ".velocity"), key + ".velocity", vec(fill.velocity) + " m/s",
        step.too_far("a particle of the fill", "its radius", norm(fill.velocity), r_default));
  }
}

// Every particle the scene starts with, and the fed ones.
void check_particles(const Scene& s, const StepMotion& step, std::vector<std::string>& errors) {
  std::size_t from_files = 0;
  for (const FillSpec& fill : s.file_fills) from_files += static_cast<std::size_t>(fill.count);
  const std::size_t tables = s.particles.size() - std::min(from_files, s.particles.size());
  check_tables(s, tables, step, errors);
  std::size_t first = tables;
  for (const FillSpec& fill : s.file_fills) {
    check_rows(s, fill, first, step, errors);
    first += static_cast<std::size_t>(fill.count);
  }
  for (const FillSpec& fill : s.fills) {
    const std::string key = "fill[" + std::to_string(fill.index) + "].velocity";
    add(errors, where(s, key), key, vec(fill.velocity) + " m/s",
        step.too_far("a particle of the fill", "its radius", norm(fill.velocity), fill.radius_min));
  }
  if (s.feed.present) {
    add(errors, where(s, "feed.velocity"), "feed.velocity", vec(s.feed.velocity) + " m/s",
        step.too_far("a fed particle", "its radius", norm(s.feed.velocity), s.feed.radius_min));
  }
}

// The smallest particle the run can have: placed, fed, or a fragment of the smallest breakable.
double smallest_radius(const Scene& s, const ParticleStore& p) {
  double r = HUGE_VAL;
  for (std::size_t k = 0; k < p.size(); ++k) r = std::min(r, p.radius[k]);
  if (s.feed.present) r = std::min(r, s.feed.radius_min);
  if (s.breakage.present) {
    r = std::min(r, smallest_fragment_radius(s.breakage));
  }
  return r;
}

// [[wall]] velocities and the drum's rim speed against the smallest particle.
void check_walls(const Scene& s, double r_min, const StepMotion& step,
                 std::vector<std::string>& errors) {
  if (!(r_min < HUGE_VAL)) return;
  const std::string radius_of = "the smallest particle's radius";
  for (std::size_t k = 0; k < s.walls.size(); ++k) {
    const std::string key = "wall[" + std::to_string(k) + "].velocity";
    add(errors, where(s, key), key, vec(s.walls[k].velocity) + " m/s",
        step.too_far("the wall", radius_of, norm(s.walls[k].velocity), r_min, "one step"));
  }
  if (!s.drum.present) return;
  const double rim = std::abs(s.drum.speed) * s.drum.radius;
  for (const char* key : {"drum.speed", "drum.speed_rpm", "drum.critical_fraction"}) {
    if (!s.where.contains(key)) continue;
    const std::string speed = num(s.drum.speed) + " rad/s";
    const std::string problem = step.too_far("the shell (rim speed " + num(rim, 3) + " m/s)",
                                             radius_of, rim, r_min, "one step");
    if (problem.empty()) return;
    errors.push_back(where(s, key) + ": error: " + key +
                     (key == std::string("drum.speed") ? " = " + speed : " gives " + speed) + ": " +
                     problem);
    return;
  }
}

}  // namespace

void validate_start(const Scene& scene, const ParticleStore& particles, double dt) {
  if (!(dt > 0.0)) return;
  const StepMotion step(scene, dt);
  std::vector<std::string> errors;
  check_particles(scene, step, errors);
  check_walls(scene, smallest_radius(scene, particles), step, errors);
  const double steps = scene.run.duration / dt;
  if (!(steps > 0.5)) {  // the run loop steps while t + dt / 2 < duration
    errors.push_back(error_at(scene, "run.duration",
                              " = " + num(scene.run.duration) + " s is " + num(steps, 3) +
                                  " of a step of " + step.dt_text() +
                                  " and rounds to no step: the run would do nothing; the "
                                  "duration must be at least one step"));
  } else if (steps > kMaxRunSteps) {
    errors.push_back(error_at(
        scene, "run.duration",
        " = " + num(scene.run.duration) + " s is " + num(steps, 3) + " steps of " + step.dt_text() +
            "; at most " + num(kMaxRunSteps) +
            " steps are allowed (days of wall time at the fastest a step goes): shorten the "
            "duration" +
            (scene.run.dt_auto ? std::string() : ", or give a larger run.dt")));
  }
  if (!errors.empty()) throw InputError(errors);
}

std::vector<std::string> output_interval_notes(const Scene& scene, double dt) {
  std::vector<std::string> notes;
  if (!(dt > 0.0)) return notes;
  const OutputSpec& out = scene.output;
  const std::pair<const char*, double> intervals[] = {
      {"output.series_interval", out.series_interval},
      {"output.snapshot_interval", out.snapshot_interval},
      {"output.checkpoint_interval", out.checkpoint_interval}};
  for (const auto& [key, interval] : intervals) {
    if (!scene.where.contains(key) || !(interval > 0.0) || interval >= dt) continue;
    notes.push_back(where(scene, key) + ": note: " + key + " = " + num(interval) +
                    " s is shorter than one step, " + StepMotion(scene, dt).dt_text() +
                    ": written every step (an output comes at most once a step)");
  }
  return notes;
}

}  // namespace dem2d
