// Deck reader and writer (src/io/deck.*, particle_csv.*, run_json.*): every key resolved,
// defaults, each kind of error with its exact location, --set overrides, CSV packings, the
// resolved deck read back to the same values, run.json.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "core/base/errors.hpp"
#include "io/deck.hpp"
#include "io/deck_schema.hpp"
#include "io/particle_csv.hpp"
#include "io/run_json.hpp"
#include "io/text.hpp"

namespace dem2d {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;

// The messages of the InputError that parsing `text` throws (none: a test failure).
std::vector<std::string> deck_errors(const std::string& text,
                                     const std::vector<std::string>& overrides = {},
                                     const std::string& path = "deck.in") {
  try {
    parse_deck_string(text, path, overrides);
  } catch (const InputError& e) {
    return e.messages();
  }
  ADD_FAILURE() << "expected an InputError for:\n" << text;
  return {};
}

::testing::AssertionResult has_message(const std::vector<std::string>& messages,
                                       const std::string& expected) {
  for (const auto& m : messages) {
    if (m == expected) return ::testing::AssertionSuccess();
  }
  auto failure = ::testing::AssertionFailure() << "no message\n  " << expected << "\namong\n";
  for (const auto& m : messages) failure << "  " << m << "\n";
  return failure;
}

// A scratch folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            (std::string("dem2d_test_deck_") + info->name() + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path file = path_ / name;
    std::ofstream(file) << text;
    return file;
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// A small valid deck: one material, one particle, nothing else.
const std::string kMinimalDeck = R"(
[[material]]
name = "steel"
density = 7800.0
youngs_modulus = 2.0e11

[[particle]]
material = "steel"
radius = 0.1
position = [0.0, 0.5]
)";

// Every table and most keys, with a CSV packing beside it.
const std::string kFullDeck = R"(title = "Thesis scene: cataracting"

[run]
duration = 10.0
dt = 1.0e-5
integrator = "iterative"
tolerance = 1.0e-7
max_passes = 30
seed = 42
gravity = [0, -9.81]
skin = 0.01
dt_safety = 0.25
allow_unsafe_dt = true

[contact]
model = "hertz-mindlin"
rolling = "constant"
rolling_damping = 0.4

[[material]]
name = "steel"
density = 7800.0
youngs_modulus = 2.0e11
poisson_ratio = 0.25
restitution = 0.73
sliding_friction = 0.1
rolling_friction = 0.05

[[material]]
name = "liner"
density = 7000
youngs_modulus = 1.0e11
shear_modulus = 4.0e10

[[interaction]]
materials = ["steel", "liner"]
restitution = 0.6
sliding_friction = 0.6

[drum]
radius = 2.5
center = [0.1, -0.2]
speed_rpm = 20.0
ramp_time = 0.5
sides = 12
angle = 15.0
material = "liner"

[[drum.lifter]]
count = 8
height = 0.1
width = 0.05
angle = 22.5
material = "steel"

[[fill]]
material = "steel"
count = 240
radius_min = 0.08
radius_max = 0.12
region = "box"
box_min = [-1.0, -2.0]
box_max = [1.0, 0.0]
velocity = [0.0, -1.0]

[[fill]]
material = "steel"
fill_fraction = 0.2
radius = 0.1
region = "annulus"

[[fill]]
file = "packing.csv"
material = "steel"
velocity = [0.5, 0.0]

[[particle]]
material = "liner"
radius = 0.2
position = [0.0, 0.5]
velocity = [0.0, -2.0]
spin = 3.0

[[wall]]
from = [-1.0, 0.0]
to = [1.0, 0.0]
material = "steel"
velocity = [0.1, 0.0]

[breakage]
material = "liner"
minimum_energy = 0.2
strength = 2.0
fragments_mean = 3.5
fragments_sd = 0.5
fragments_min = 2
fragments_max = 5
minimum_radius = 0.03
start = 0.5

[feed]
material = "liner"
period = 0.5
radius_min = 0.04
radius_max = 0.06
start = 1.0
point = [0.0, 1.0]
velocity = [0.0, -1.0]

[sieve]
material = "liner"
box_min = [-0.4, -0.5]
box_max = [0.5, 0.6]
aperture = 0.03

[output]
directory = "out/waterfall"
series_interval = 2.0e-3
snapshot_interval = 0.05
checkpoint_interval = 0.0
progress_interval = 10.0
)";

const std::string kPackingCsv =
    "x, y, radius, vy, material\n"
    "0.0, 0.0, 0.1, 1.5, liner\n"
    "\n"
    "# a comment line\n"
    "0.3, -0.1, 0.05, 0.0,\n";

// Every key of one table of two scenes, compared through the deck's description
// (deck_schema.hpp), so that a new key is compared without a line here. Values are compared in
// the deck's units (degrees, "auto"), exactly.
template <class T>
void expect_same_keys(const deck::Table<T>& spec, const T& a, const T& b,
                      const std::string& where) {
  for (const deck::Key<T>& key : spec.keys) {
    if (key.field.load == nullptr) continue;  // never written back (speed_rpm)
    const std::optional<deck::Value> x = key.field.load(a);
    const std::optional<deck::Value> y = key.field.load(b);
    EXPECT_TRUE(x == y) << where << "." << key.name << ": " << (x ? deck::toml_text(*x) : "unset")
                        << " vs " << (y ? deck::toml_text(*y) : "unset");
  }
}

template <class T>
void expect_same_keys(const deck::Table<T>& spec, const std::vector<T>& a, const std::vector<T>& b,
                      const std::string& where) {
  ASSERT_EQ(a.size(), b.size()) << where;
  for (std::size_t i = 0; i < a.size(); ++i) {
    expect_same_keys(spec, a[i], b[i], where + "[" + std::to_string(i) + "]");
  }
}

// Every value of two scenes, except where they came from (deck_path, source lines).
void expect_same_values(const Scene& a, const Scene& b) {
  expect_same_keys(deck::kTopLevel, a, b, "");
  expect_same_keys(deck::kRun, a.run, b.run, "run");
  expect_same_keys(deck::kContact, a.contact, b.contact, "contact");
  expect_same_keys(deck::kMaterial, a.materials, b.materials, "material");
  expect_same_keys(deck::kInteraction, a.interactions, b.interactions, "interaction");
  EXPECT_EQ(a.drum.present, b.drum.present);
  expect_same_keys(deck::kDrum, a.drum, b.drum, "drum");
  expect_same_keys(deck::kLifter, a.drum.lifters, b.drum.lifters, "drum.lifter");
  expect_same_keys(deck::kFill, a.fills, b.fills, "fill");
  expect_same_keys(deck::kFill, a.file_fills, b.file_fills, "fill (file)");
  expect_same_keys(deck::kParticle, a.particles, b.particles, "particle");
  expect_same_keys(deck::kWall, a.walls, b.walls, "wall");
  expect_same_keys(deck::kOutput, a.output, b.output, "output");
}

// ---------------------------------------------------------------------------------------------
// Valid decks

TEST(Deck, FullDeckResolvesEveryValue) {
  const TempDir dir;
  dir.write("packing.csv", kPackingCsv);
  const fs::path deck = dir.write("full.in", kFullDeck);
  const Scene s = load_deck(deck.string());

  EXPECT_EQ(s.deck_path, deck.string());
  EXPECT_EQ(s.title, "Thesis scene: cataracting");
  EXPECT_EQ(s.run.duration, 10.0);
  EXPECT_FALSE(s.run.dt_auto);
  EXPECT_EQ(s.run.dt, 1.0e-5);
  EXPECT_EQ(s.run.integrator, IntegratorKind::kIterative);
  EXPECT_EQ(s.run.tolerance, 1.0e-7);
  EXPECT_EQ(s.run.max_passes, 30);
  EXPECT_EQ(s.run.seed, 42u);
  EXPECT_EQ(s.run.gravity, (Vec2{0.0, -9.81}));  // an integer accepted as a float
  EXPECT_EQ(s.run.skin, 0.01);
  EXPECT_EQ(s.run.dt_safety, 0.25);
  EXPECT_TRUE(s.run.allow_unsafe_dt);
  EXPECT_EQ(s.contact.model, ContactModelKind::kHertzMindlin);
  EXPECT_EQ(s.contact.rolling, RollingModelKind::kConstant);
  EXPECT_EQ(s.contact.rolling_damping, 0.4);

  ASSERT_EQ(s.materials.size(), 2u);
  const MaterialSpec& steel = s.materials[0];
  EXPECT_EQ(steel.name, "steel");
  EXPECT_EQ(steel.density, 7800.0);
  EXPECT_EQ(steel.youngs_modulus, 2.0e11);
  EXPECT_EQ(steel.poisson_ratio, 0.25);
  EXPECT_DOUBLE_EQ(steel.shear_modulus, 8.0e10);  // G = E / (2 (1 + nu))
  EXPECT_EQ(steel.restitution, 0.73);
  EXPECT_EQ(steel.sliding_friction, 0.1);
  EXPECT_EQ(steel.rolling_friction, 0.05);
  const MaterialSpec& liner = s.materials[1];
  EXPECT_EQ(liner.density, 7000.0);
  EXPECT_EQ(liner.shear_modulus, 4.0e10);
  EXPECT_DOUBLE_EQ(liner.poisson_ratio, 0.25);  // nu = E / (2 G) - 1
  EXPECT_EQ(liner.restitution, 0.5);            // default

  ASSERT_EQ(s.interactions.size(), 1u);
  EXPECT_EQ(s.interactions[0].material_a, "steel");
  EXPECT_EQ(s.interactions[0].material_b, "liner");
  EXPECT_EQ(s.interactions[0].restitution, 0.6);
  EXPECT_EQ(s.interactions[0].sliding_friction, 0.6);
  EXPECT_FALSE(s.interactions[0].rolling_friction.has_value());

  EXPECT_TRUE(s.drum.present);
  EXPECT_EQ(s.drum.radius, 2.5);
  EXPECT_EQ(s.drum.center, (Vec2{0.1, -0.2}));
  EXPECT_DOUBLE_EQ(s.drum.speed, 20.0 * 2.0 * kPi / 60.0);  // rpm -> rad/s
  EXPECT_EQ(s.drum.ramp_time, 0.5);
  EXPECT_EQ(s.drum.sides, 12);
  EXPECT_DOUBLE_EQ(s.drum.angle, kPi / 12.0);  // 15 degrees
  EXPECT_EQ(s.drum.material, "liner");
  ASSERT_EQ(s.drum.lifters.size(), 1u);
  EXPECT_EQ(s.drum.lifters[0].count, 8);
  EXPECT_EQ(s.drum.lifters[0].height, 0.1);
  EXPECT_EQ(s.drum.lifters[0].width, 0.05);
  EXPECT_DOUBLE_EQ(s.drum.lifters[0].angle, kPi / 8.0);  // 22.5 degrees
  EXPECT_EQ(s.drum.lifters[0].material, "steel");

  ASSERT_EQ(s.fills.size(), 2u);  // the file fill is not among them
  EXPECT_EQ(s.fills[0].count, 240);
  EXPECT_EQ(s.fills[0].radius_min, 0.08);
  EXPECT_EQ(s.fills[0].radius_max, 0.12);
  EXPECT_EQ(s.fills[0].region, FillRegion::kBox);
  EXPECT_EQ(s.fills[0].box_min, (Vec2{-1.0, -2.0}));
  EXPECT_EQ(s.fills[0].box_max, (Vec2{1.0, 0.0}));
  EXPECT_EQ(s.fills[0].velocity, (Vec2{0.0, -1.0}));
  EXPECT_EQ(s.fills[0].source_line, 56);  // the [[fill]] header
  EXPECT_EQ(s.fills[1].fill_fraction, 0.2);
  EXPECT_EQ(s.fills[1].count, 0);
  EXPECT_EQ(s.fills[1].radius_min, 0.1);
  EXPECT_EQ(s.fills[1].radius_max, 0.1);
  EXPECT_EQ(s.fills[1].region, FillRegion::kAnnulus);

  ASSERT_EQ(s.file_fills.size(), 1u);
  EXPECT_EQ(s.file_fills[0].file, fs::absolute(dir.path() / "packing.csv").string());
  EXPECT_EQ(s.file_fills[0].count, 2);

  // The [[particle]] first, then the CSV rows.
  ASSERT_EQ(s.particles.size(), 3u);
  EXPECT_EQ(s.particles[0].material, "liner");
  EXPECT_EQ(s.particles[0].radius, 0.2);
  EXPECT_EQ(s.particles[0].position, (Vec2{0.0, 0.5}));
  EXPECT_EQ(s.particles[0].velocity, (Vec2{0.0, -2.0}));
  EXPECT_EQ(s.particles[0].spin, 3.0);
  EXPECT_EQ(s.particles[0].source_line, 77);
  EXPECT_EQ(s.particles[1].material, "liner");  // from the material column
  EXPECT_EQ(s.particles[1].position, (Vec2{0.0, 0.0}));
  EXPECT_EQ(s.particles[1].radius, 0.1);
  EXPECT_EQ(s.particles[1].velocity, (Vec2{0.5, 1.5}));  // vx from the fill, vy from the file
  EXPECT_EQ(s.particles[1].source_line, 2);
  EXPECT_EQ(s.particles[2].material, "steel");  // empty field: the fill's material
  EXPECT_EQ(s.particles[2].position, (Vec2{0.3, -0.1}));
  EXPECT_EQ(s.particles[2].radius, 0.05);
  EXPECT_EQ(s.particles[2].source_line, 5);

  ASSERT_EQ(s.walls.size(), 1u);
  EXPECT_EQ(s.walls[0].from, (Vec2{-1.0, 0.0}));
  EXPECT_EQ(s.walls[0].to, (Vec2{1.0, 0.0}));
  EXPECT_EQ(s.walls[0].velocity, (Vec2{0.1, 0.0}));

  EXPECT_EQ(s.output.directory, "out/waterfall");
  EXPECT_EQ(s.output.series_interval, 2.0e-3);
  EXPECT_EQ(s.output.snapshot_interval, 0.05);
  EXPECT_EQ(s.output.checkpoint_interval, 0.0);
  EXPECT_EQ(s.output.progress_interval, 10.0);
}

TEST(Deck, DefaultsAreFilledIn) {
  const Scene s = parse_deck_string(kMinimalDeck, "min.in");
  EXPECT_EQ(s.title, "");
  EXPECT_EQ(s.run.duration, 1.0);
  EXPECT_TRUE(s.run.dt_auto);
  EXPECT_EQ(s.run.dt, 0.0);
  EXPECT_EQ(s.run.integrator, IntegratorKind::kVerlet);
  EXPECT_EQ(s.run.tolerance, 1.0e-6);
  EXPECT_EQ(s.run.max_passes, 20);
  EXPECT_EQ(s.run.seed, 1u);
  EXPECT_EQ(s.run.gravity, (Vec2{0.0, -9.81}));
  EXPECT_EQ(s.run.skin, -1.0);  // the core chooses
  EXPECT_EQ(s.run.dt_safety, 0.2);
  EXPECT_FALSE(s.run.allow_unsafe_dt);
  EXPECT_EQ(s.contact.model, ContactModelKind::kHertzMindlin);
  EXPECT_EQ(s.contact.rolling, RollingModelKind::kEpsd);
  EXPECT_EQ(s.contact.rolling_damping, 0.3);
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].poisson_ratio, 0.25);
  EXPECT_DOUBLE_EQ(s.materials[0].shear_modulus, 8.0e10);
  EXPECT_EQ(s.materials[0].restitution, 0.5);
  EXPECT_EQ(s.materials[0].sliding_friction, 0.5);
  EXPECT_EQ(s.materials[0].rolling_friction, 0.0);
  EXPECT_EQ(s.materials[0].normal_stiffness, 0.0);
  EXPECT_FALSE(s.drum.present);
  EXPECT_TRUE(s.fills.empty());
  ASSERT_EQ(s.particles.size(), 1u);
  EXPECT_EQ(s.particles[0].velocity, (Vec2{0.0, 0.0}));
  EXPECT_EQ(s.particles[0].spin, 0.0);
  EXPECT_EQ(s.particles[0].source_line, 7);
  EXPECT_EQ(s.output.directory, "out");
  EXPECT_EQ(s.output.series_interval, 1.0e-3);
  EXPECT_EQ(s.output.snapshot_interval, 0.0);
  EXPECT_EQ(s.output.checkpoint_interval, 0.0);
  EXPECT_EQ(s.output.progress_interval, 5.0);
}

TEST(Deck, DrumSpeedFromCriticalFraction) {
  // w = f sqrt(|g| / R), the classical critical speed of a point on the shell.
  const Scene s = parse_deck_string(kMinimalDeck + R"(
[drum]
radius = 2.5
critical_fraction = 0.75
material = "steel"
)",
                                    "deck.in", {"run.gravity=[3.0, -4.0]"});
  EXPECT_DOUBLE_EQ(s.drum.speed, 0.75 * std::sqrt(5.0 / 2.5));
  EXPECT_EQ(s.drum.sides, 0);
  EXPECT_EQ(s.drum.angle, 0.0);
}

TEST(Deck, ThesisAndLinearModelsTakeTheirCoefficients) {
  const Scene thesis = parse_deck_string(R"(
[contact]
model = "thesis"
rolling = "none"
[[material]]
name = "ore"
density = 4800
youngs_modulus = 6.0e10
damping_normal = 0.2
damping_tangential = 0.3
)" + kMinimalDeck.substr(kMinimalDeck.find("[[particle]]")),
                                         "deck.in", {"particle.0.material=ore"});
  EXPECT_EQ(thesis.contact.model, ContactModelKind::kThesis);
  EXPECT_EQ(thesis.contact.rolling, RollingModelKind::kNone);
  EXPECT_EQ(thesis.materials[0].damping_normal, 0.2);
  EXPECT_EQ(thesis.materials[0].damping_tangential, 0.3);

  const Scene linear = parse_deck_string(
      kMinimalDeck, "deck.in", {"contact.model=linear", "material.steel.normal_stiffness=1e6"});
  EXPECT_EQ(linear.materials[0].normal_stiffness, 1.0e6);
}

// ---------------------------------------------------------------------------------------------
// Errors: each with its exact location and key

TEST(DeckErrors, MissingFile) {
  try {
    load_deck("/nonexistent/deck.in");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    ASSERT_EQ(e.messages().size(), 1u);
    EXPECT_EQ(e.messages()[0],
              "/nonexistent/deck.in: error: cannot open deck: No such file or directory");
  }
}

TEST(DeckErrors, TomlSyntaxErrorHasItsPosition) {
  const auto messages = deck_errors("[run]\nduration = 1.0\ndt = [1.0,\n");
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0],
            "deck.in:3:12: error: Error while parsing array: encountered end-of-file (in [run]: "
            "dt = [1.0,)");

  const auto twice = deck_errors("[run]\nduration = 1.0\nduration = 2.0\n");
  ASSERT_EQ(twice.size(), 1u);
  EXPECT_EQ(twice[0],
            "deck.in:3:12: error: Error while parsing key-value pair: cannot redefine "
            "existing floating-point 'duration' (in [run]: duration = 2.0)");

  // A header line is shown as it is, and a line before any table alone.
  const auto header = deck_errors("title = \"x\"\n[run\nduration = 1\n");
  ASSERT_EQ(header.size(), 1u);
  EXPECT_EQ(header[0],
            "deck.in:2:5: error: Error while parsing table header: expected ']', saw "
            "'\\n' (the line: [run)");
}

// Placement before step 1: a particle outside the drum, overlapping its polygonal shell by more
// than 5 % of its radius, coinciding with another or overlapping it by more than 5 % of the
// smaller radius is bad input at its position; a particle inside the circle but outside the
// polygon is caught by the sides.
TEST(DeckErrors, ParticlesOutsideTheDrumOrOnEachOtherAreRefused) {
  std::string deck = R"([[material]]
name = "steel"
density = 7800.0
youngs_modulus = 2.0e11

[drum]
radius = 1.0
sides = 8
material = "steel"
)";
  for (const char* xy : {"[0.0, 0.0]", "[0.0, 0.0]", "[0.15, 0.0]", "[0.0, -0.9]", "[0.0, 3.0]",
                         "[0.7853, 0.3253]", "[0.0, 0.5]", "[0.0, 0.6985]"})
    deck += fmt::format("[[particle]]\nmaterial = \"steel\"\nradius = 0.1\nposition = {}\n", xy);
  const auto messages = deck_errors(deck);
  EXPECT_TRUE(has_message(messages,
                          "deck.in:17:12: error: particle[1].position = [0.0, 0.0]: coincides with "
                          "particle[0] (line 10); give each particle its own place"));
  EXPECT_TRUE(
      has_message(messages,
                  "deck.in:21:12: error: particle[2].position = [0.15, 0.0]: overlaps particle[0] "
                  "(line 10) by 50 % of the smaller radius; at most 5 % is allowed at the start"));
  EXPECT_TRUE(has_message(
      messages,
      "deck.in:25:12: error: particle[3].position = [0.0, -0.9]: the particle (radius "
      "0.1 m) overlaps the shell of the drum (radius 1 m about [0, 0], 8 sides) by 7.61 % of "
      "its radius; at most 5 % is allowed at the start"));
  EXPECT_TRUE(
      has_message(messages,
                  "deck.in:29:12: error: particle[4].position = [0.0, 3.0]: the particle (radius "
                  "0.1 m) lies outside the drum (radius 1 m about [0, 0], 8 sides); place it at "
                  "least its radius inside the shell"));
  // particle[5] is 0.85 from the centre towards the middle of a side: 0.15 inside the circle
  // but 0.074 from the side (apothem 0.924), less than its radius.
  EXPECT_TRUE(
      has_message(messages,
                  "deck.in:33:12: error: particle[5].position = [0.7853, 0.3253]: the particle "
                  "(radius 0.1 m) overlaps the shell of the drum (radius 1 m about [0, 0], 8 "
                  "sides) by 26.1 % of its radius; at most 5 % is allowed at the start"));
  // particle[6] at [0, 0.5] and particle[7] 0.1985 from it overlap by 0.75 %: a resting contact,
  // accepted. particle[2] overlaps both particle[0] and particle[1].
  EXPECT_EQ(messages.size(), 6u) << fmt::format("{}", fmt::join(messages, "\n"));
}

TEST(DeckErrors, OutOfRangeValue) {
  const auto messages = deck_errors(R"(
[run]
duration = -1
dt_safety = 1.5
)" + kMinimalDeck);
  EXPECT_TRUE(has_message(messages, "deck.in:3:12: error: run.duration = -1: must be > 0"));
  EXPECT_TRUE(has_message(messages, "deck.in:4:13: error: run.dt_safety = 1.5: must be in (0, 1]"));
  EXPECT_EQ(messages.size(), 2u);
}

TEST(DeckErrors, WrongTypes) {
  const auto messages = deck_errors(R"(title = 3
[run]
dt = "fast"
max_passes = 2.5
gravity = [0.0, -9.81, 0.0]
allow_unsafe_dt = "yes"
)" + kMinimalDeck);
  EXPECT_TRUE(has_message(messages, "deck.in:1:9: error: title = 3: expected a string"));
  EXPECT_TRUE(has_message(
      messages, "deck.in:3:6: error: run.dt = \"fast\": expected a number > 0 (s) or \"auto\""));
  EXPECT_TRUE(
      has_message(messages, "deck.in:4:14: error: run.max_passes = 2.5: expected an integer >= 1"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:5:11: error: run.gravity = [0.0, -9.81, 0.0]: "
                          "expected an array of two numbers [x, y]"));
  EXPECT_TRUE(has_message(
      messages, "deck.in:6:19: error: run.allow_unsafe_dt = \"yes\": expected true or false"));
  EXPECT_EQ(messages.size(), 5u);
}

TEST(DeckErrors, ChoiceListsTheAllowedWords) {
  const auto messages =
      deck_errors("[contact]\nmodel = \"hertz\"\nrolling = \"EPSD\"\n" + kMinimalDeck);
  EXPECT_TRUE(has_message(messages,
                          "deck.in:2:9: error: contact.model = \"hertz\": must be one "
                          "of \"hertz-mindlin\", \"thesis\", \"linear\""));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:3:11: error: contact.rolling = \"EPSD\": must be one of "
                          "\"epsd\", \"constant\", \"none\"; did you mean \"epsd\"?"));
}

TEST(DeckErrors, MisspeltKeySuggestsTheRightOne) {
  const auto messages = deck_errors(R"(
[[material]]
name = "steel"
density = 7800.0
youngs_modulus = 2.0e11
restituion = 0.7

[runn]
duration = 1.0

[[particle]]
material = "steel"
radius = 0.1
position = [0.0, 0.5]
veloctiy = [1.0, 0.0]
colour = "red"
)");
  EXPECT_TRUE(has_message(messages,
                          "deck.in:6:1: error: unknown key 'restituion' in "
                          "[[material]]; did you mean 'restitution'?"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:8:2: error: unknown table [runn]; did you mean "
                          "[run]?"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:15:1: error: unknown key 'veloctiy' in "
                          "[[particle]]; did you mean 'velocity'?"));
  EXPECT_TRUE(
      has_message(messages,
                  "deck.in:16:1: error: unknown key 'colour' in [[particle]]; "
                  "valid keys: material, shape, radius, semi_axes, exponent, angle, position, "
                  "velocity, spin"));
  EXPECT_EQ(messages.size(), 4u);
}

TEST(DeckErrors, MissingRequiredKeyIsReportedAtTheTable) {
  const auto messages = deck_errors(R"(
[[material]]
name = "steel"
youngs_modulus = 2.0e11

[[particle]]
material = "steel"
position = [0.0, 0.5]
)");
  EXPECT_TRUE(
      has_message(messages, "deck.in:2:1: error: material[0].density is required (a number > 0)"));
  EXPECT_TRUE(has_message(
      messages, "deck.in:6:1: error: particle[0].radius is required (a number >= 1e-09)"));
  EXPECT_EQ(messages.size(), 2u);
}

TEST(DeckErrors, UnknownMaterialListsTheDefinedOnes) {
  const auto messages = deck_errors(kMinimalDeck + R"(
[[material]]
name = "liner"
density = 7000.0
youngs_modulus = 1.0e11

[[wall]]
from = [-1.0, 0.0]
to = [1.0, 0.0]
material = "stell"

[[interaction]]
materials = ["steel", "rubber"]
)");
  EXPECT_TRUE(has_message(messages,
                          "deck.in:20:12: error: wall[0].material = \"stell\": no such "
                          "material; did you mean \"steel\"? (defined: \"steel\", "
                          "\"liner\")"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:23:23: error: interaction[0].materials[1] = "
                          "\"rubber\": no such material (defined: \"steel\", "
                          "\"liner\")"));
  EXPECT_EQ(messages.size(), 2u);
}

TEST(DeckErrors, MaterialElasticity) {
  const auto messages = deck_errors(R"(
[[material]]
name = "a"
density = 1.0
youngs_modulus = 1.0e9
poisson_ratio = 0.3
shear_modulus = 4.0e8

[[material]]
name = "b"
density = 1.0
youngs_modulus = 1.0e9
shear_modulus = 1.0e8

[[material]]
name = "a"
density = 1.0
youngs_modulus = 1.0e9
poisson_ratio = 0.5

[[particle]]
material = "a"
radius = 0.1
position = [0.0, 0.0]
)");
  EXPECT_TRUE(has_message(messages,
                          "deck.in:7:17: error: material[0]: give poisson_ratio or "
                          "shear_modulus, not both"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:13:17: error: material[1].shear_modulus = 1.0e8: "
                          "gives poisson_ratio = youngs_modulus / (2 shear_modulus) - "
                          "1 = 4, which must be in [0, 0.5) (3.33333e+08 < "
                          "shear_modulus <= 5e+08)"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:16:8: error: material[2].name = \"a\": already the "
                          "name of material[0]"));
  EXPECT_TRUE(has_message(
      messages, "deck.in:19:17: error: material[2].poisson_ratio = 0.5: must be in [0, 0.5)"));
  EXPECT_EQ(messages.size(), 4u);
}

TEST(DeckErrors, CoefficientOfAnotherContactModel) {
  const auto messages = deck_errors(R"(
[contact]
model = "thesis"

[[material]]
name = "steel"
density = 7800.0
youngs_modulus = 2.0e11
restitution = 0.7
normal_stiffness = 1e6
)" + kMinimalDeck.substr(kMinimalDeck.find("[[particle]]")));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:9:15: error: material[0].restitution = 0.7: not "
                          "used by contact.model = \"thesis\", which takes "
                          "damping_normal and damping_tangential"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:10:20: error: material[0].normal_stiffness = 1e6: "
                          "not used by contact.model = \"thesis\", which takes "
                          "damping_normal and damping_tangential"));
  EXPECT_EQ(messages.size(), 2u);
}

TEST(DeckErrors, DrumKeys) {
  const auto messages = deck_errors(kMinimalDeck + R"(
[drum]
radius = 2.5
speed = 1.0
speed_rpm = 10.0
sides = 2
ramp_time = -1.0
material = "steel"

[[drum.lifter]]
count = 0
height = 3.0
width = 0.1
)");
  EXPECT_TRUE(has_message(messages,
                          "deck.in:15:13: error: drum.speed_rpm = 10.0: give only one of "
                          "speed, speed_rpm and critical_fraction (found speed and "
                          "speed_rpm)"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:16:9: error: drum.sides = 2: must be 0 (a circle) "
                          "or >= 3 (a regular polygon)"));
  EXPECT_TRUE(has_message(messages, "deck.in:17:13: error: drum.ramp_time = -1.0: must be >= 0"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:21:9: error: drum.lifter[0].count = 0: must be >= "
                          "1"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:22:10: error: drum.lifter[0].height = 3.0: must be "
                          "< drum.radius = 2.5"));
  EXPECT_EQ(messages.size(), 5u);
}

// Lifter bars stand apart: within a set (the thesis's 12 bars of 0.1 m pass, a set wider than
// its spacing does not), across sets (two sets at the same angle), and each narrower than the
// drum's diameter. A set that fits exactly, bars touching at their top corners, passes.
TEST(DeckErrors, LifterBarsStandApart) {
  const std::string drum = kMinimalDeck + R"(
[drum]
radius = 1.0
material = "steel"
)";
  const auto lifters = [&](const std::string& sets) { return drum + sets; };
  EXPECT_NO_THROW(parse_deck_string(lifters(R"(
[[drum.lifter]]
count = 12
height = 0.1
width = 0.1
[[drum.lifter]]
count = 12
height = 0.05
width = 0.1
angle = 15.0
)"),
                                    "deck.in"));
  // A bar spans 2 atan(0.25 / 0.7) = 0.686 rad at its top corners: 2 pi / 0.686 = 9.16, so 9
  // bars fit and 10 do not.
  EXPECT_NO_THROW(parse_deck_string(
      lifters("[[drum.lifter]]\ncount = 9\nheight = 0.3\nwidth = 0.5\n"), "deck.in"));
  auto messages = deck_errors(lifters("[[drum.lifter]]\ncount = 10\nheight = 0.3\nwidth = 0.5\n"));
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0],
            "deck.in:16:9: error: drum.lifter[0].count = 10: the 10 bars of width 0.5 m overlap "
            "their neighbours: 10 x 0.5 m = 5 m of bars around the circle of their top faces, "
            "4.4 m long (radius 0.7 m); at most 9 bars of this width fit there apart (or, for 10 "
            "bars, a width below 0.455 m)");
  messages = deck_errors(lifters(R"(
[[drum.lifter]]
count = 8
height = 0.1
width = 0.1
[[drum.lifter]]
count = 4
height = 0.2
width = 0.05
angle = 90.0
)"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:24:9: error: drum.lifter[1].angle = 90.0: bar 0 of "
                          "drum.lifter[1] overlaps bar 2 of drum.lifter[0]; give the sets angles "
                          "that keep their bars apart"));
  EXPECT_EQ(messages.size(), 1u);
  // The top face 0.9 m from the centre: its corners stay inside the shell up to a width of
  // 2 sqrt(1 - 0.81) = 0.872 m.
  messages = deck_errors(lifters("[[drum.lifter]]\ncount = 1\nheight = 0.1\nwidth = 0.9\n"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:18:9: error: drum.lifter[0].width = 0.9: must be < 0.872 m: "
                          "wider, the corners of a bar's top face (0.9 m from the centre) lie "
                          "outside the shell (drum.radius = 1)"));
  EXPECT_EQ(messages.size(), 1u);
}

// A material's name holds no '.', ',', '=' or control character; anything else is a name.
TEST(DeckErrors, MaterialNamesTheSnapshotsCanList) {
  for (const std::string name : {"iron ore", "rubber-liner", "Stahl (hart)", "ore_2"}) {
    const std::string deck = R"(
[[material]]
name = ")" + name + R"("
density = 7800.0
youngs_modulus = 2.0e11
[[particle]]
material = ")" + name + R"("
radius = 0.1
position = [0.0, 0.5]
)";
    EXPECT_NO_THROW(parse_deck_string(deck, "deck.in")) << name;
  }
  for (const std::string name : {"a,b", "a=b", "a.b", "a\\tb", "a\\nb", ""}) {
    const auto messages =
        deck_errors("[[material]]\nname = \"" + name + "\"\ndensity = 1.0\nyoungs_modulus = 1.0\n");
    ASSERT_FALSE(messages.empty()) << name;
    EXPECT_TRUE(messages[0].starts_with("deck.in:2:8: error: material[0].name = ") &&
                messages[0].ends_with(
                    ": must be a non-empty name without '.', ',', '=' or control characters "
                    "(letters, digits, spaces and other punctuation are allowed)"))
        << messages[0];
  }
}

TEST(DeckErrors, FillKeys) {
  const auto messages = deck_errors(kMinimalDeck + R"(
[[fill]]
material = "steel"
count = 10
fill_fraction = 0.3
radius = 0.1

[[fill]]
material = "steel"
fill_fraction = 0.3
radius_min = 0.2
radius_max = 0.1
region = "box"
box_min = [0.0, 0.0]
box_max = [1.0, 0.0]

[[fill]]
material = "steel"
count = 5
radius = 0.1
)");
  EXPECT_TRUE(has_message(messages,
                          "deck.in:12:1: error: fill[0]: give only one of count, "
                          "fill_fraction, bed_filling and file (found count and fill_fraction)"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:15:17: error: fill[0].fill_fraction = 0.3: needs "
                          "a [drum] (it is a fraction of the drum's area)"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:21:14: error: fill[1].radius_min = 0.2: must be <= "
                          "radius_max = 0.1"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:25:11: error: fill[1].box_max = [1.0, 0.0]: must be "
                          "above and to the right of box_min = [0.0, 0.0]"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:27:1: error: fill[2]: the default region "
                          "\"bottom\" needs a [drum]; without one, use region = "
                          "\"box\" with box_min and box_max"));
  // Also: fill[1].fill_fraction needs a drum, and so does fill[0]'s default region.
  EXPECT_TRUE(has_message(messages,
                          "deck.in:20:17: error: fill[1].fill_fraction = 0.3: needs "
                          "a [drum] (it is a fraction of the drum's area)"));
  EXPECT_EQ(messages.size(), 7u);
}

// A drum deck with one [[fill]] whose keys are `fill_keys`.
std::string drum_fill_deck(const std::string& fill_keys) {
  return kMinimalDeck +
         "\n[drum]\nradius = 1.0\nmaterial = \"steel\"\n\n[[fill]]\nmaterial = "
         "\"steel\"\n" +
         fill_keys;
}

TEST(Deck, ShapesAreRead) {
  const Scene s = parse_deck_string(kMinimalDeck + R"(
[[particle]]
material = "steel"
shape = "superellipse"
semi_axes = [0.1, 0.05]
exponent = 8
angle = 30
position = [0.5, 0.5]

[drum]
radius = 2.0
material = "steel"

[[fill]]
material = "steel"
count = 10
radius = 0.05
shape = "superellipse"
aspect = 0.5
exponent = 4
)",
                                    "shapes.in");
  ASSERT_EQ(s.particles.size(), 2u);
  EXPECT_FALSE(s.particles[0].shaped());
  const ParticleSpec& p = s.particles[1];
  EXPECT_TRUE(p.shaped());
  EXPECT_EQ(p.semi_a, 0.1);
  EXPECT_EQ(p.semi_b, 0.05);
  EXPECT_EQ(p.exponent, 8.0);
  EXPECT_EQ(p.angle, 30.0 * kRadiansPerDegree);
  ASSERT_EQ(s.fills.size(), 1u);
  EXPECT_EQ(s.fills[0].shape, ParticleShape::kSuperellipse);
  EXPECT_EQ(s.fills[0].aspect, 0.5);
  EXPECT_EQ(s.fills[0].exponent, 4.0);
  EXPECT_TRUE(has_shaped_particles(s));
  EXPECT_FALSE(has_shaped_particles(parse_deck_string(kMinimalDeck, "discs.in")));
}

TEST(DeckErrors, ShapeKeys) {
  const auto messages = deck_errors(kMinimalDeck + R"(
[[particle]]
material = "steel"
shape = "superellipse"
radius = 0.1
semi_axes = [0.1, -0.05]
position = [0.5, 0.5]

[[particle]]
material = "steel"
radius = 0.1
exponent = 4
angle = 10
position = [-0.5, 0.5]

[[particle]]
material = "steel"
shape = "superellipse"
exponent = 1.5
position = [0.5, -0.5]

[[particle]]
material = "steel"
shape = "ellipse"
radius = 0.1
position = [-0.5, -0.5]

[drum]
radius = 2.0
material = "steel"

[[fill]]
material = "steel"
count = 5
radius = 0.05
aspect = 0.5

[[fill]]
material = "steel"
count = 5
radius = 0.05
shape = "superellipse"
aspect = 1.5
)");
  EXPECT_TRUE(has_message(messages,
                          "deck.in:15:10: error: particle[1].radius = 0.1: not used by shape = "
                          "\"superellipse\" (semi_axes = [a, b] give its size)"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:16:13: error: particle[1].semi_axes = [0.1, -0.05]: "
                          "each semi-axis must be >= 1e-09 m"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:22:12: error: particle[2].exponent = 4: used only by shape = "
                          "\"superellipse\" (the shape is \"disc\", the default)"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:23:9: error: particle[2].angle = 10: used only by shape = "
                          "\"superellipse\" (the shape is \"disc\", the default)"));
  EXPECT_TRUE(has_message(
      messages,
      "deck.in:26:1: error: particle[3].semi_axes is required (an array of two numbers [x, y])"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:29:12: error: particle[3].exponent = 1.5: must be in [2, 50]"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:34:9: error: particle[4].shape = \"ellipse\": must be one of "
                          "\"disc\", \"superellipse\""));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:46:10: error: fill[0].aspect = 0.5: used only by shape = "
                          "\"superellipse\" (the shape is \"disc\", the default)"));
  EXPECT_EQ(messages.size(), 9u);
  EXPECT_TRUE(
      has_message(messages, "deck.in:53:10: error: fill[1].aspect = 1.5: must be in (0, 1]"));
}

TEST(Deck, ShellIsRead) {
  const Scene s = parse_deck_string(kMinimalDeck + R"(
[[material]]
name = "liner"
density = 7850.0
youngs_modulus = 2.1e11
poisson_ratio = 0.3

[drum]
radius = 2.0
material = "steel"

[[drum.lifter]]
count = 4
height = 0.1
width = 0.05

[shell]
thickness = 0.05
material = "liner"
depth = 0.1
elements_through_thickness = 3
)",
                                    "shell.in");
  ASSERT_TRUE(s.shell.present);
  EXPECT_EQ(s.shell.thickness, 0.05);
  EXPECT_EQ(s.shell.material, "liner");
  EXPECT_EQ(s.shell.depth, 0.1);
  EXPECT_EQ(s.shell.elements_through_thickness, 3);
  EXPECT_FALSE(s.shell.element_size.has_value()) << "the thickness, by default";
  EXPECT_FALSE(parse_deck_string(kMinimalDeck, "bare.in").shell.present);
}

TEST(DeckErrors, ShellKeys) {
  const std::string drum = R"(
[drum]
radius = 1.0
material = "steel"
)";
  const std::string lifter = R"(
[[drum.lifter]]
count = 4
height = 0.1
width = 0.05
)";
  // Without a drum; without lifters; on a polygon; a wall too thick; missing keys.
  EXPECT_TRUE(has_message(deck_errors(kMinimalDeck + "[shell]\nthickness = 0.05\ndepth = 0.1\n"),
                          "deck.in:11:1: error: a [shell] needs a [drum]: it is the "
                          "drum's wall"));
  EXPECT_TRUE(
      has_message(deck_errors(kMinimalDeck + drum + "[shell]\nthickness = 0.05\ndepth = 0.1\n"),
                  "deck.in:15:1: error: a [shell] reports per lifter bar (lifters.csv): the drum "
                  "needs [[drum.lifter]]"));
  EXPECT_TRUE(
      has_message(deck_errors(kMinimalDeck + drum + "sides = 8\n" + lifter +
                              "[shell]\nthickness = 0.05\ndepth = 0.1\n"),
                  "deck.in:21:1: error: a [shell] needs a round drum (drum.sides = 0); the drum is "
                  "a 8-gon"));
  EXPECT_TRUE(has_message(
      deck_errors(kMinimalDeck + drum + lifter + "[shell]\nthickness = 0.5\ndepth = 0.1\n"),
      "deck.in:21:13: error: shell.thickness = 0.5: must be below half the drum radius 1 m"));
  EXPECT_TRUE(
      has_message(deck_errors(kMinimalDeck + drum + lifter +
                              "[shell]\nthickness = 0.05\ndepth = 0.1\nelement_size = 1e-5\n"),
                  "deck.in:23:16: error: shell.element_size = 1e-5: must lie between 0.000314159 m "
                  "(20 000 elements around the ring) and a quarter of the drum radius, 0.25 m"));
  const auto missing = deck_errors(kMinimalDeck + drum + lifter + "[shell]\nmaterial = \"rock\"\n");
  EXPECT_TRUE(
      has_message(missing, "deck.in:20:1: error: shell.thickness is required (a number > 0)"));
  EXPECT_TRUE(has_message(missing, "deck.in:20:1: error: shell.depth is required (a number > 0)"));
  EXPECT_EQ(missing.size(), 3u);
  EXPECT_TRUE(has_message(missing,
                          "deck.in:21:12: error: shell.material = \"rock\": no such "
                          "material (defined: \"steel\")"));
}

TEST(DeckErrors, FillBedFilling) {
  // Beside a fill fraction, out of range, and without a drum.
  auto messages =
      deck_errors(drum_fill_deck("bed_filling = 0.3\nfill_fraction = 0.2\nradius = 0.05\n"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:16:1: error: fill[0]: give only one of count, fill_fraction, "
                          "bed_filling and file (found fill_fraction and bed_filling)"))
      << messages[0];
  messages = deck_errors(drum_fill_deck("bed_filling = 1.0\nradius = 0.05\n"));
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0], "deck.in:18:15: error: fill[0].bed_filling = 1.0: must be in (0, 1)");
  messages = deck_errors(kMinimalDeck +
                         "[[fill]]\nmaterial = \"steel\"\nbed_filling = 0.3\nradius = 0.05\n"
                         "region = \"box\"\nbox_min = [0, 0]\nbox_max = [1, 1]\n");
  EXPECT_TRUE(has_message(messages,
                          "deck.in:13:15: error: fill[0].bed_filling = 0.3: needs a [drum] (it is "
                          "a fraction of the drum's area)"));
}

TEST(DeckErrors, FillSizeDistributions) {
  // Keys of another law; a d50 outside the truncation; a missing spread.
  auto messages = deck_errors(drum_fill_deck(
      "count = 10\nsize_distribution = \"normal\"\nd50 = 0.5\nradius = 0.05\nradius_min = "
      "0.01\nradius_max = 0.03\ngeometric_sd = 1.5\n"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:21:10: error: fill[0].radius = 0.05: not used by "
                          "size_distribution = \"normal\", which takes d50, sigma, radius_min "
                          "and radius_max"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:24:16: error: fill[0].geometric_sd = 1.5: not used by "
                          "size_distribution = \"normal\", which takes d50, sigma, radius_min "
                          "and radius_max"));
  EXPECT_TRUE(
      has_message(messages, "deck.in:16:1: error: fill[0].sigma is required (a number > 0)"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:20:7: error: fill[0].d50 = 0.5: must lie within [2 radius_min, "
                          "2 radius_max] = [0.02, 0.06] m (a diameter, within the truncation)"));
  messages = deck_errors(drum_fill_deck("count = 10\nradius = 0.05\nd50 = 0.1\n"));
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0],
            "deck.in:20:7: error: fill[0].d50 = 0.1: not used by size_distribution = "
            "\"uniform\" (the default), which takes radius, or radius_min and radius_max");
  messages = deck_errors(drum_fill_deck(
      "count = 10\nsize_distribution = \"lognormal\"\nd50 = 0.04\ngeometric_sd = 1.0\n"
      "radius_min = 0.02\nradius_max = 0.02\n"));
  EXPECT_TRUE(
      has_message(messages, "deck.in:21:16: error: fill[0].geometric_sd = 1.0: must be > 1"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:22:14: error: fill[0].radius_min = 0.02: must be < radius_max "
                          "= 0.02 (the truncation of the lognormal law)"));
}

TEST(DeckErrors, FillSizeTable) {
  auto messages = deck_errors(drum_fill_deck(
      "count = 10\nsize_distribution = \"table\"\nsizes = [0.02, 0.04]\nmass_fractions = [0.5, "
      "0.4999]\n"));
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0],
            "deck.in:21:18: error: fill[0].mass_fractions = [0.5, 0.4999]: sum to 0.9999; must "
            "sum to 1 (within 1e-9)");
  messages = deck_errors(drum_fill_deck(
      "count = 10\nsize_distribution = \"table\"\nsizes = [0.04, 0.02, -1]\nmass_fractions = "
      "[0.5, 0.5]\nradius = 0.1\n"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:20:9: error: fill[0].sizes = [0.04, 0.02, -1]: element 2 = -1: "
                          "expected a finite number >= 2e-09"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:22:10: error: fill[0].radius = 0.1: not used by "
                          "size_distribution = \"table\", which takes sizes and mass_fractions"));
  messages = deck_errors(drum_fill_deck(
      "count = 10\nsize_distribution = \"table\"\nsizes = [0.04, 0.02]\nmass_fractions = "
      "[0.5, 0.25, 0.25]\n"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:20:9: error: fill[0].sizes = [0.04, 0.02]: must be in "
                          "increasing order, each size once (diameters, m)"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:21:18: error: fill[0].mass_fractions = [0.5, 0.25, 0.25]: 3 "
                          "values for 2 sizes; give one per size"));
}

TEST(DeckErrors, FillMix) {
  auto messages = deck_errors(drum_fill_deck("count = 10\nradius = 0.05\nmix = true\n"));
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0],
            "deck.in:20:7: error: fill[0].mix = true: the first [[fill]] has no fill before it "
            "to mix with");
  messages =
      deck_errors(drum_fill_deck("count = 10\nradius = 0.05\n\n[[fill]]\nmaterial = "
                                 "\"steel\"\ncount = 5\nradius = 0.02\nregion = "
                                 "\"annulus\"\nmix = true\n"));
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0],
            "deck.in:26:7: error: fill[1].mix = true: fill[0] is placed in another region; "
            "mixed fills share their region (and box)");
}

TEST(Deck, FillSizesBedFillingAndMixAreRead) {
  const Scene s = parse_deck_string(
      drum_fill_deck("bed_filling = 0.35\nsize_distribution = \"table\"\nsizes = [0.02, 0.04]\n"
                     "mass_fractions = [0.25, 0.75]\n\n[[fill]]\nmaterial = \"steel\"\ncount = "
                     "20\nsize_distribution = \"lognormal\"\nd50 = 0.03\ngeometric_sd = 1.4\n"
                     "radius_min = 0.01\nradius_max = 0.02\nmix = true\n"),
      "deck.in");
  ASSERT_EQ(s.fills.size(), 2u);
  EXPECT_EQ(s.fills[0].bed_filling, 0.35);
  EXPECT_EQ(s.fills[0].count, 0);
  EXPECT_EQ(s.fills[0].size_distribution, SizeDistribution::kTable);
  EXPECT_EQ(s.fills[0].sizes, (std::vector<double>{0.02, 0.04}));
  EXPECT_EQ(s.fills[0].mass_fractions, (std::vector<double>{0.25, 0.75}));
  EXPECT_EQ(s.fills[0].radius_min, 0.01);  // half the sizes: the lattice's spacing
  EXPECT_EQ(s.fills[0].radius_max, 0.02);
  EXPECT_FALSE(s.fills[0].mix);
  EXPECT_EQ(s.fills[1].size_distribution, SizeDistribution::kLognormal);
  EXPECT_EQ(s.fills[1].d50, 0.03);
  EXPECT_EQ(s.fills[1].geometric_sd, 1.4);
  EXPECT_TRUE(s.fills[1].mix);
}

// --set fill.0.bed_filling replaces the deck's count or fill_fraction, as fill_fraction does.
TEST(DeckOverrides, BedFillingReplacesCountAndFillFraction) {
  for (const std::string source : {"count = 10\n", "fill_fraction = 0.2\n"}) {
    const Scene s = parse_deck_string(drum_fill_deck(source + "radius = 0.05\n"), "deck.in",
                                      {"fill.0.bed_filling=0.3"});
    EXPECT_EQ(s.fills[0].bed_filling, 0.3);
    EXPECT_EQ(s.fills[0].count, 0);
    EXPECT_EQ(s.fills[0].fill_fraction, 0.0);
    EXPECT_TRUE(s.where.at("fill[0].bed_filling").starts_with("--set fill.0.bed_filling=0.3"));
  }
  const Scene s = parse_deck_string(drum_fill_deck("bed_filling = 0.3\nradius = 0.05\n"), "deck.in",
                                    {"fill.0.count=7"});
  EXPECT_EQ(s.fills[0].count, 7);
  EXPECT_EQ(s.fills[0].bed_filling, 0.0);
}

TEST(DeckErrors, WallsAndOutput) {
  const auto messages = deck_errors(kMinimalDeck + R"(
[[wall]]
from = [1.0, 1.0]
to = [1, 1]
material = "steel"

[output]
checkpoint_interval = -1.0
series_interval = 0
)");
  EXPECT_TRUE(has_message(messages,
                          "deck.in:14:6: error: wall[0].to = [1, 1]: must differ from "
                          "wall.from (a wall has a length)"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:18:23: error: output.checkpoint_interval = -1.0: must be >= 0"));
  EXPECT_TRUE(
      has_message(messages, "deck.in:19:19: error: output.series_interval = 0: must be > 0"));
  EXPECT_EQ(messages.size(), 3u);
}

TEST(DeckErrors, NoPositionForTheDeckAsAWhole) {
  const auto messages = deck_errors("title = \"empty\"\n");
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0], "deck.in: error: no particles: add a [[fill]] or a [[particle]] table");

  const auto no_material = deck_errors(
      "[[particle]]\nmaterial = \"steel\"\nradius = 0.1\n"
      "position = [0.0, 0.0]\n");
  ASSERT_EQ(no_material.size(), 1u);
  EXPECT_EQ(no_material[0],
            "deck.in: error: no [[material]] is defined; every [[fill]], "
            "[[particle]], [[wall]] and the [drum] name one");
}

TEST(DeckErrors, TablesOfTheWrongKind) {
  const auto messages = deck_errors(R"(
run = 5
[material]
name = "steel"
[[drum]]
radius = 1.0
)");
  EXPECT_TRUE(has_message(messages, "deck.in:2:7: error: run = 5: expected a table [run]"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:3:1: error: material: expected an array of "
                          "tables: write [[material]], not [material]"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:5:1: error: drum: expected one table [drum], not "
                          "an array of tables [[drum]]"));
}

TEST(DeckErrors, AllErrorsAreReportedInOneThrow) {
  const auto messages = deck_errors(R"(
[run]
duration = 0.0
integrator = "euler"

[[material]]
name = "steel"
density = -7800.0
youngs_modulus = 2.0e11
sliding_fricton = 0.1

[[particle]]
material = "steel"
radius = -0.1
position = [0.0]
)");
  ASSERT_EQ(messages.size(), 6u);
  EXPECT_TRUE(has_message(messages, "deck.in:3:12: error: run.duration = 0.0: must be > 0"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:4:14: error: run.integrator = \"euler\": must be "
                          "one of \"verlet\", \"iterative\""));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:8:11: error: material[0].density = -7800.0: must "
                          "be > 0"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:10:1: error: unknown key 'sliding_fricton' in "
                          "[[material]]; did you mean 'sliding_friction'?"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:14:10: error: particle[0].radius = -0.1: must be "
                          ">= 1e-09"));
  EXPECT_TRUE(has_message(messages,
                          "deck.in:15:12: error: particle[0].position = [0.0]: "
                          "expected an array of two numbers [x, y]"));
}

// ---------------------------------------------------------------------------------------------
// --set overrides

TEST(DeckOverrides, ByDottedPathNameAndIndex) {
  const Scene s =
      parse_deck_string(kMinimalDeck + R"(
[[material]]
name = "liner"
density = 7000.0
youngs_modulus = 1.0e11

[drum]
radius = 2.5
speed = 1.0
material = "liner"

[[drum.lifter]]
count = 4
height = 0.1
width = 0.1

[[fill]]
material = "steel"
count = 10
radius = 0.1
)",
                        "deck.in",
                        {"drum.speed=1.5", "run.dt=auto", "run.duration = 2",
                         "material.liner.restitution=0.4", "material.0.density=5000",
                         "fill.0.count=100", "drum.lifter.0.height=0.2", "run.gravity=[0, -1.5]",
                         "title=sweep 3", "output.directory='runs/a b'", "fill.0.region=full"});
  EXPECT_EQ(s.drum.speed, 1.5);
  EXPECT_TRUE(s.run.dt_auto);
  EXPECT_EQ(s.run.duration, 2.0);
  EXPECT_EQ(s.materials[1].restitution, 0.4);
  EXPECT_EQ(s.materials[0].density, 5000.0);
  EXPECT_EQ(s.fills[0].count, 100);
  EXPECT_EQ(s.fills[0].region, FillRegion::kFull);
  EXPECT_EQ(s.drum.lifters[0].height, 0.2);
  EXPECT_EQ(s.run.gravity, (Vec2{0.0, -1.5}));
  EXPECT_EQ(s.title, "sweep 3");  // not one TOML value: a bare string
  EXPECT_EQ(s.output.directory, "runs/a b");

  // A later --set of the same key wins.
  const Scene twice = parse_deck_string(kMinimalDeck, "deck.in", {"run.seed=3", "run.seed=4"});
  EXPECT_EQ(twice.run.seed, 4u);
}

TEST(DeckOverrides, ErrorsNameTheOption) {
  const auto messages =
      deck_errors(kMinimalDeck + R"(
[drum]
radius = 2.5
material = "steel"
)",
                  {"drum.sped=1.5", "drum.radius=-1", "material.stel.density=1",
                   "particle.3.radius=1", "run.dt", "contact.model=hertz", "drum.radius.x=1",
                   "wall.0.from=[0, 0]", "material=1", "nonsense.key=1"});
  EXPECT_TRUE(has_message(messages,
                          "--set drum.sped=1.5: error: unknown key 'sped' in [drum]; "
                          "did you mean 'speed'?"));
  EXPECT_TRUE(has_message(messages, "--set drum.radius=-1: error: drum.radius = -1: must be > 0"));
  EXPECT_TRUE(has_message(messages,
                          "--set material.stel.density=1: error: no [[material]] "
                          "element 'stel'; give an index 0 to 0 or a name: \"steel\""));
  EXPECT_TRUE(has_message(messages,
                          "--set particle.3.radius=1: error: no [[particle]] element "
                          "'3'; give an index 0 to 0"));
  EXPECT_TRUE(
      has_message(messages, "--set run.dt: error: expected KEY=VALUE, e.g. drum.speed=1.5"));
  EXPECT_TRUE(has_message(messages,
                          "--set contact.model=hertz: error: contact.model = "
                          "\"hertz\": must be one of \"hertz-mindlin\", \"thesis\", "
                          "\"linear\""));
  EXPECT_TRUE(
      has_message(messages, "--set drum.radius.x=1: error: drum.radius is a value, not a table"));
  EXPECT_TRUE(
      has_message(messages, "--set wall.0.from=[0, 0]: error: the deck has no [[wall]] table"));
  EXPECT_TRUE(has_message(messages,
                          "--set material=1: error: cannot set all of [[material]]; "
                          "set one key of one element: material.INDEX.KEY"));
  EXPECT_TRUE(has_message(messages,
                          "--set nonsense.key=1: error: unknown table [nonsense]; "
                          "valid keys: title, run, contact, material, interaction, "
                          "drum, fill, particle, wall, breakage, feed, sieve, shell, output"));
  EXPECT_EQ(messages.size(), 10u);
}

TEST(DeckOverrides, OverrideCanCreateATable) {
  const Scene s =
      parse_deck_string(kMinimalDeck, "deck.in", {"drum.radius=2", "drum.material=steel"});
  EXPECT_TRUE(s.drum.present);
  EXPECT_EQ(s.drum.radius, 2.0);
  EXPECT_EQ(s.drum.material, "steel");

  // A table made by --set is located at the option that made it.
  const auto messages = deck_errors(kMinimalDeck, {"drum.radius=2"});
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0], "--set drum.radius=2: error: drum.material is required (a string)");
}

// ---------------------------------------------------------------------------------------------
// CSV packings

TEST(DeckCsv, ErrorsCarryTheFileLine) {
  const TempDir dir;
  dir.write("bad.csv",
            "x,y,radius,material\n"
            "0.0,0.0,0.1,steel\n"
            "abc,0.0,0.1,steel\n"
            "0.0,0.0,-0.1,steel\n"
            "0.0,0.0,0.1,stel\n"
            "0.0,0.0\n");
  dir.write("header.csv", "x,y,raduis\n0,0,0.1\n");
  dir.write("nomaterial.csv", "x,y,radius\n0,0,0.1\n");
  const fs::path deck = dir.write("deck.in", kMinimalDeck + R"(
[[fill]]
file = "bad.csv"

[[fill]]
file = "header.csv"
material = "steel"

[[fill]]
file = "nomaterial.csv"

[[fill]]
file = "missing.csv"
material = "steel"
)");
  std::vector<std::string> messages;
  try {
    load_deck(deck.string());
  } catch (const InputError& e) {
    messages = e.messages();
  }
  const std::string d = deck.string();
  const std::string bad = (dir.path() / "bad.csv").string();
  EXPECT_TRUE(
      has_message(messages, bad + ":3: error: fill[0].file row: column 'x' = \"abc\": expected "
                                  "a number"));
  EXPECT_TRUE(has_message(messages, bad +
                                        ":4: error: fill[0].file row: column 'radius' = -0.1: must "
                                        "be >= 1e-09"));
  EXPECT_TRUE(has_message(
      messages, bad + ":5: error: fill[0].file row: column 'material' = \"stel\": no such "
                      "material; did you mean \"steel\"? (defined: "
                      "\"steel\")"));
  EXPECT_TRUE(
      has_message(messages, bad + ":6: error: fill[0].file row: 2 fields, expected 4 as in the "
                                  "header"));
  EXPECT_TRUE(has_message(
      messages, (dir.path() / "header.csv").string() +
                    ":1: error: fill[1].file header: unknown column 'raduis'; did you mean "
                    "'radius'? (columns: x, y, radius, vx, vy, spin, "
                    "material)"));
  EXPECT_TRUE(has_message(messages, d + ":19:1: error: fill[2].material is required: " +
                                        (dir.path() / "nomaterial.csv").string() +
                                        " has no material column"));
  EXPECT_TRUE(has_message(messages, d +
                                        ":23:8: error: fill[3].file = \"missing.csv\": cannot "
                                        "open " +
                                        (dir.path() / "missing.csv").string() +
                                        ": No such file or directory"));
  EXPECT_EQ(messages.size(), 7u);
}

// RFC 4180 quoting: a field in double quotes may hold commas, and a doubled quote inside it is
// one quote; spaces around a quoted field are dropped. A quote left open is an error at its line.
TEST(DeckCsv, QuotedFieldsFollowRfc4180) {
  const std::vector<std::string> materials = {"steel, hardened", "say \"hi\"", "ore"};
  const CsvPacking good = read_particle_csv(
      "\"x\",\"y\",\"radius\",material\n"
      "0.0,0.0,0.1,\"steel, hardened\"\n"
      "\"1.5\", \"-2\" ,0.2,\"say \"\"hi\"\"\"\n"
      "2.0,0.0,0.1,ore\n"
      "3.0,0.0,0.1,\"\"\n",
      "q.csv", materials, CsvDefaults{"ore", {}}, "fill[0].file");
  EXPECT_TRUE(good.errors.empty()) << fmt::format("{}", fmt::join(good.errors, "\n"));
  ASSERT_EQ(good.particles.size(), 4u);
  EXPECT_EQ(good.particles[0].material, "steel, hardened");
  EXPECT_EQ(good.particles[1].position, (Vec2{1.5, -2.0}));
  EXPECT_EQ(good.particles[1].radius, 0.2);
  EXPECT_EQ(good.particles[1].material, "say \"hi\"");
  EXPECT_EQ(good.particles[2].material, "ore");
  EXPECT_EQ(good.particles[3].material, "ore");  // "" quoted is an empty field: the default
  EXPECT_EQ(good.particles[3].source_line, 5);

  const CsvPacking bad = read_particle_csv(
      "x,y,radius,material\n"
      "0.0,0.0,0.1,\"steel, hardened\n"
      "0.0,0.0,0.1,\"ore\"x\n"
      "0.0,0.0,0.1,\"iron, ore\"\n",
      "q.csv", materials, CsvDefaults{}, "fill[0].file");
  ASSERT_EQ(bad.errors.size(), 3u) << fmt::format("{}", fmt::join(bad.errors, "\n"));
  EXPECT_EQ(bad.errors[0],
            "q.csv:2: error: fill[0].file row: field 4 opens a quote that the line does not "
            "close");
  EXPECT_EQ(bad.errors[1],
            "q.csv:3: error: fill[0].file row: field 4 has text after its closing quote");
  EXPECT_TRUE(bad.errors[2].starts_with(
      "q.csv:4: error: fill[0].file row: column 'material' = \"iron, ore\": no such material"))
      << bad.errors[2];
}

TEST(DeckCsv, FileFillRejectsPlacementKeys) {
  const TempDir dir;
  dir.write("p.csv", "x,y,radius\n0,0,0.1\n");
  const auto messages = deck_errors(kMinimalDeck + R"(
[[fill]]
file = "p.csv"
material = "steel"
radius = 0.1
)",
                                    {}, (dir.path() / "deck.in").string());
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0], (dir.path() / "deck.in").string() +
                             ":15:10: error: fill[0].radius = 0.1: not used by a fill from a "
                             "file (the file gives each particle)");
}

// ---------------------------------------------------------------------------------------------
// Resolved deck and run.json

// parse(resolved(parse(x))) has the values of parse(x), bit for bit.
void expect_round_trip(const TempDir& dir, const std::string& text,
                       const std::vector<std::string>& overrides = {}) {
  const Scene first = load_deck(dir.write("original.in", text).string(), overrides);
  const std::string resolved = resolved_deck_toml(first);
  SCOPED_TRACE(resolved);
  Scene second;
  try {
    second = load_deck(dir.write("resolved.in", resolved).string());
  } catch (const InputError& e) {
    FAIL() << e.what();
  }
  expect_same_values(first, second);
  EXPECT_EQ(resolved_deck_toml(second), resolved);
}

TEST(DeckResolved, ReadsBackToTheSameValues) {
  const TempDir dir;
  dir.write("packing.csv", kPackingCsv);
  expect_round_trip(dir, kFullDeck);
  // Angles and speeds that do not convert exactly, a random seed, a fraction of the area.
  expect_round_trip(dir, kFullDeck,
                    {"drum.angle=33.3", "drum.lifter.0.angle=-7.1", "drum.ramp_time=0.1",
                     "run.seed=9007199254740993", "fill.1.fill_fraction=0.37"});
}

TEST(DeckResolved, ReadsBackOtherModelsAndDerivedValues) {
  const TempDir dir;
  // Thesis model, shear modulus given, critical fraction, dt = "auto", lifter of the drum's
  // material, no interactions, a box fill with a radius range.
  expect_round_trip(dir, R"(
[run]
dt = "auto"
gravity = [0.3, -9.7]
[contact]
model = "thesis"
rolling = "none"
[[material]]
name = "ore"
density = 4800.0
youngs_modulus = 6.0e10
shear_modulus = 2.4e10
damping_normal = 0.1
damping_tangential = 0.12
sliding_friction = 0.3
[drum]
radius = 1.7
critical_fraction = 0.65
sides = 7
angle = -12.34
material = "ore"
[[drum.lifter]]
count = 3
height = 0.05
width = 0.02
angle = 1.0e-3
[[fill]]
material = "ore"
count = 50
radius_min = 0.01
radius_max = 0.03
region = "box"
box_min = [-0.5, -1.0]
box_max = [0.5, -0.2]
[[wall]]
from = [0, 0]
to = [0.1, 0.3]
material = "ore"
)");
  // Linear model with a stiffness, and a speed in rpm.
  expect_round_trip(dir, kMinimalDeck + R"(
[contact]
model = "linear"
[drum]
radius = 1.0
speed_rpm = 17.3
material = "steel"
)",
                    {"material.steel.normal_stiffness=3.3e5", "material.steel.restitution=0.9"});
}

TEST(DeckResolved, ReadsBackFillSizesBedFillingAndMix) {
  const TempDir dir;
  expect_round_trip(
      dir, drum_fill_deck("bed_filling = 0.35\nsize_distribution = \"table\"\nsizes = [0.02, "
                          "0.04]\nmass_fractions = [0.25, 0.75]\n\n[[fill]]\nmaterial = "
                          "\"steel\"\ncount = 20\nsize_distribution = \"lognormal\"\nd50 = "
                          "0.03\ngeometric_sd = 1.4\nradius_min = 0.01\nradius_max = 0.02\n"
                          "mix = true\n\n[[fill]]\nmaterial = \"steel\"\ncount = 20\n"
                          "size_distribution = \"normal\"\nd50 = 0.03\nsigma = 0.005\n"
                          "radius_min = 0.01\nradius_max = 0.02\n"));
}

TEST(DeckResolved, ReadsBackShapes) {
  const TempDir dir;
  expect_round_trip(dir, drum_fill_deck("count = 10\nradius = 0.05\nshape = \"superellipse\"\n"
                                        "aspect = 0.6\nexponent = 3.5\n\n[[particle]]\n"
                                        "material = \"steel\"\nshape = \"superellipse\"\n"
                                        "semi_axes = [0.1, 0.04]\nangle = 12.5\n"
                                        "position = [0.2, -0.3]\n"));
}

TEST(DeckResolved, WritesEveryDefault) {
  const std::string resolved = resolved_deck_toml(parse_deck_string(kMinimalDeck, "min.in"));
  for (const char* line :
       {"dt = \"auto\"", "integrator = \"verlet\"", "gravity = [0.0, -9.81]",
        "model = \"hertz-mindlin\"", "rolling = \"epsd\"", "poisson_ratio = 0.25",
        "restitution = 0.5", "youngs_modulus = 2e11", "velocity = [0.0, 0.0]",
        "directory = \"out\"", "series_interval = 0.001", "checkpoint_interval = 0.0"}) {
    EXPECT_NE(resolved.find(std::string("\n") + line + "\n"), std::string::npos) << line;
  }
  EXPECT_EQ(resolved.find("skin"), std::string::npos);  // unset: the core chooses
  EXPECT_EQ(resolved.find("[drum]"), std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// The description itself (deck_schema.hpp)

// The keys that code after the per-key pass reads, and those the resolved deck never writes.
bool read_by_code(std::string_view path) {
  return path == "drum.critical_fraction" || path == "fill.file";
}
bool never_written(std::string_view path) {
  return path == "drum.speed_rpm" || path == "drum.critical_fraction";
}

std::string dotted(std::string_view table, std::string_view key) {
  return table.empty() ? std::string(key) : std::string(table) + "." + std::string(key);
}

TEST(DeckDescription, TablesAndKeysAreConsistent) {
  std::vector<std::pair<std::string, bool>> tables, named;  // path, repeated
  deck::for_each_table([&](const auto& table) {
    tables.emplace_back(std::string(table.path), table.repeated);
    std::vector<std::string_view> seen;
    for (const auto& key : table.keys) {
      const std::string path = dotted(table.path, key.name);
      SCOPED_TRACE(path);
      EXPECT_EQ(std::count(seen.begin(), seen.end(), key.name), 0) << "named twice";
      seen.push_back(key.name);
      if (key.type == deck::Type::kTable || key.type == deck::Type::kTableArray) {
        named.emplace_back(path, key.type == deck::Type::kTableArray);
        continue;
      }
      EXPECT_EQ(key.type == deck::Type::kChoice, !key.choices.empty());
      EXPECT_EQ(key.field.store == nullptr, read_by_code(path));
      EXPECT_EQ(key.field.load == nullptr, never_written(path));
      if (key.need == deck::Need::kRequired) {
        EXPECT_TRUE(key.default_text.empty());
      }
    }
  });
  // Every sub-table key names a described table of its kind, and every table but the top
  // level is named by one.
  for (const auto& sub : named) {
    EXPECT_NE(std::find(tables.begin(), tables.end(), sub), tables.end()) << sub.first;
  }
  for (const auto& table : tables) {
    if (table.first.empty()) continue;
    EXPECT_NE(std::find(named.begin(), named.end(), table), named.end()) << table.first;
  }
}

// Values of the key's type inside its range, as a person types them (33.3, not
// 30.299999999999997: an angle comes back as the shortest degrees that give the same radians).
template <class T>
std::vector<deck::Value> sample_values(const deck::Key<T>& key) {
  const deck::Bound& b = key.range;
  const double lo = std::isfinite(b.lo) ? b.lo : 0.0;
  const double inside = std::isfinite(b.hi)   ? (lo + b.hi) / 2.0
                        : std::isfinite(b.lo) ? lo + 2.5
                                              : 33.3;
  switch (key.type) {
    case deck::Type::kNumber:
      return {inside};
    case deck::Type::kNumberOrAuto:
      return {inside, std::string("auto")};
    case deck::Type::kInteger:
      return {static_cast<std::int64_t>(lo) + 2};
    case deck::Type::kBool:
      return {true, false};
    case deck::Type::kChoice:
      return {std::string(key.choices.front()), std::string(key.choices.back())};
    case deck::Type::kVector:
      return {Vec2{1.5, -2.5}};
    case deck::Type::kMaterialPair:
      return {deck::Names{"a", "b"}};
    case deck::Type::kNumberList:
      return {deck::Numbers{0.25, 0.75}, deck::Numbers{1.5}};
    default:
      return {std::string("steel")};
  }
}

template <class T>
void expect_fields_round_trip(const deck::Table<T>& table) {
  for (const deck::Key<T>& key : table.keys) {
    if (key.field.store == nullptr || key.field.load == nullptr) continue;
    for (const deck::Value& value : sample_values(key)) {
      T target{};
      key.field.store(target, value);
      const std::optional<deck::Value> back = key.field.load(target);
      EXPECT_TRUE(back && *back == value)
          << dotted(table.path, key.name) << ": stored " << deck::toml_text(value) << ", loaded "
          << (back ? deck::toml_text(*back) : "nothing");
    }
  }
}

// Each key's field takes a value of the key's type and gives the same back, in the deck's units
// (an angle in degrees, "auto"): a field of the wrong type would throw or drift here.
TEST(DeckDescription, EveryFieldStoresAndLoadsItsType) {
  deck::for_each_table([](const auto& table) { expect_fields_round_trip(table); });
}

// How --set names a key of a table's first element, and how messages name it.
std::string set_path(std::string_view table, bool repeated, std::string_view key) {
  if (table.empty()) return std::string(key);
  return std::string(table) + (repeated ? ".0." : ".") + std::string(key);
}
std::string message_path(std::string_view table, bool repeated, std::string_view key) {
  if (table.empty()) return std::string(key);
  return std::string(table) + (repeated ? "[0]." : ".") + std::string(key);
}

// One override and the message it must cause.
struct Case {
  std::string option;
  std::string message;
};

// The case for one key, or none (make_case returns an empty option).
using MakeCase = std::function<Case(
    std::string_view table, bool repeated, std::string_view key, deck::Type, const deck::Bound&,
    std::int64_t max, std::span<const std::string_view> choices, std::string_view unit)>;

// A case for every key that `model` takes and no other model's pass covers: the keys of all
// models with "hertz-mindlin" (kFullDeck's), a model's own coefficients with that model.
template <class T>
void add_cases(const deck::Table<T>& table, ContactModelKind model, const MakeCase& make_case,
               std::vector<Case>& cases) {
  for (const deck::Key<T>& key : table.keys) {
    if (key.type == deck::Type::kTable || key.type == deck::Type::kTableArray) continue;
    if (!deck::takes(key.models, model)) continue;
    if (model != ContactModelKind::kHertzMindlin && key.models == deck::kAllModels) continue;
    Case c = make_case(table.path, table.repeated, key.name, key.type, key.range, key.max,
                       key.choices, key.unit);
    if (!c.option.empty()) cases.push_back(std::move(c));
  }
}

// Loads kFullDeck under each contact model with every case's override at once and expects
// every case's message; returns the number of cases.
std::size_t expect_cases(const MakeCase& make_case) {
  const TempDir dir;
  dir.write("packing.csv", kPackingCsv);
  const fs::path deck = dir.write("full.in", kFullDeck);
  std::size_t count = 0;
  for (const auto& model : deck::kContactModels) {
    std::vector<Case> cases;
    deck::for_each_table(
        [&](const auto& table) { add_cases(table, model.value, make_case, cases); });
    std::vector<std::string> options{"contact.model=" + std::string(model.name)};
    for (const Case& c : cases) options.push_back(c.option);
    std::vector<std::string> messages;
    try {
      load_deck(deck.string(), options);
      ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
      messages = e.messages();
    }
    for (const Case& c : cases) EXPECT_TRUE(has_message(messages, c.message)) << model.name;
    count += cases.size();
  }
  return count;
}

// "--set material.0.density=0.0: error: material[0].density = 0.0: must be > 0".
Case make_case(std::string_view table, bool repeated, std::string_view key,
               const std::string& value, const std::string& shown, const std::string& what) {
  const std::string where = set_path(table, repeated, key) + "=" + value;
  return {where, "--set " + where + ": error: " + message_path(table, repeated, key) + " = " +
                     shown + ": " + what};
}

// A bounded number or integer key set just below (upper: above) its range.
Case out_of_range(bool upper, std::string_view table, bool repeated, std::string_view key,
                  deck::Type type, const deck::Bound& b, std::int64_t max) {
  const bool integer = type == deck::Type::kInteger;
  if ((type != deck::Type::kNumber && !integer) || b.unbounded()) return {};
  std::string value;
  if (!upper && std::isfinite(b.lo)) {
    value = integer ? std::to_string(static_cast<std::int64_t>(b.lo) - 1)
                    : toml_number(b.lo_open ? b.lo : b.lo - 1.0);
  } else if (upper && std::isfinite(b.hi)) {
    value = toml_number(b.hi_open ? b.hi : b.hi + 1.0);
  } else if (upper && integer && max < INT_MAX) {
    value = std::to_string(max + 1);
    return make_case(table, repeated, key, value, value, "must be <= " + std::to_string(max));
  } else {
    return {};
  }
  return make_case(table, repeated, key, value, value, "must be " + b.text());
}

// The per-key pass checks every described range, from below and from above.
TEST(DeckDescription, EveryRangeIsChecked) {
  std::size_t count = 0;
  for (const bool upper : {false, true}) {
    count += expect_cases([upper](std::string_view table, bool repeated, std::string_view key,
                                  deck::Type type, const deck::Bound& b, std::int64_t max,
                                  std::span<const std::string_view>, std::string_view) {
      return out_of_range(upper, table, repeated, key, type, b, max);
    });
  }
  EXPECT_GE(count, 50u);  // 50 when written: not none by mistake
}

// A key set to a value of another type, and the message, written here by hand from the type.
Case wrong_type(std::string_view table, bool repeated, std::string_view key, deck::Type type,
                const deck::Bound& b, std::span<const std::string_view> choices,
                std::string_view unit) {
  const std::string range = b.unbounded() ? "" : " " + b.text();
  switch (type) {
    case deck::Type::kNumber:
      return make_case(table, repeated, key, "'x'", "\"x\"", "expected a number" + range);
    case deck::Type::kInteger:
      return make_case(table, repeated, key, "2.5", "2.5", "expected an integer" + range);
    case deck::Type::kBool:
      return make_case(table, repeated, key, "2.5", "2.5", "expected true or false");
    case deck::Type::kChoice: {
      std::string words;
      for (const std::string_view w : choices) {
        words += (words.empty() ? "\"" : ", \"") + std::string(w) + "\"";
      }
      return make_case(table, repeated, key, "2.5", "2.5", "expected a string, one of " + words);
    }
    case deck::Type::kVector:
      return make_case(table, repeated, key, "2.5", "2.5",
                       "expected an array of two numbers [x, y]");
    case deck::Type::kNumberOrAuto:
      return make_case(table, repeated, key, "true", "true",
                       "expected a number" + range + " (" + std::string(unit) + ") or \"auto\"");
    case deck::Type::kMaterialPair:
      return make_case(table, repeated, key, "2.5", "2.5",
                       "expected two material names [\"a\", \"b\"]");
    case deck::Type::kNumberList:
      return make_case(table, repeated, key, "2.5", "2.5", "expected an array of numbers" + range);
    default:  // kString, kMaterial
      return make_case(table, repeated, key, "2.5", "2.5", "expected a string");
  }
}

// The per-key pass checks every described key's type.
TEST(DeckDescription, EveryTypeIsChecked) {
  const std::size_t count =
      expect_cases([](std::string_view table, bool repeated, std::string_view key, deck::Type type,
                      const deck::Bound& b, std::int64_t, std::span<const std::string_view> choices,
                      std::string_view unit) {
        return wrong_type(table, repeated, key, type, b, choices, unit);
      });
  EXPECT_GE(count, 74u);  // every key of every table (74 when written)
}

TEST(RunJson, HoldsTheRunAndTheResolvedDeck) {
  const TempDir dir;
  const Scene scene = parse_deck_string(kMinimalDeck, "min.in", {"title=a \"quoted\" title"});
  RunInfo info;
  info.version = "0.1.0";
  info.ranks = 3;
  info.wall_time_s = 12.5;
  info.steps = 1000;
  info.particle_steps_per_second = 2.0e6;
  info.dt = 1.0e-5;
  info.extra.add("final_time", "0.01");
  const fs::path path = dir.path() / "run.json";
  write_run_json(path.string(), scene, info);
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string json = buffer.str();
  for (const char* part :
       {"\"version\": \"0.1.0\",", "\"ranks\": 3,", "\"wall_time_s\": 12.5,", "\"steps\": 1000,",
        "\"particle_steps_per_second\": 2e6,", "\"dt\": 1e-5,", "\"final_time\": 0.01,",
        "\"deck\": {", "\"title\": \"a \\\"quoted\\\" title\"", "\"dt\": \"auto\"",
        "\"material\": [{", "\"gravity\": [0, -9.81]", "\"interaction\": []"}) {
    EXPECT_NE(json.find(part), std::string::npos) << part << "\n" << json;
  }
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));

  EXPECT_THROW(write_run_json((dir.path() / "no" / "such" / "run.json").string(), scene, info),
               IoError);
}

}  // namespace
}  // namespace dem2d
