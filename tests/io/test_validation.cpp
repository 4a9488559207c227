// Checks before step 1 (docs/input.md, "Checks before the run"): the placement of file rows and
// lifters (src/io/placement.cpp), the first step's motion, the step count and the memory estimate
// (src/core/validate.*), each refused with its location, key and limit.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "core/base/errors.hpp"
#include "core/geometry/drum_geometry.hpp"
#include "core/run/simulation.hpp"
#include "core/setup/fill.hpp"
#include "core/setup/validate.hpp"
#include "io/deck.hpp"

namespace dem2d {
namespace {

namespace fs = std::filesystem;

// A scratch folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() / (std::string("dem2d_test_validation_") + info->name() +
                                         "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path_ / name) << text;
    return (path_ / name).string();
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

// The messages of the InputError that `action` throws (none: a test failure).
template <class F>
std::vector<std::string> errors_of(F action) {
  try {
    action();
  } catch (const InputError& e) {
    return e.messages();
  }
  ADD_FAILURE() << "expected an InputError";
  return {};
}

std::vector<std::string> deck_errors(const std::string& text, const std::string& path = "deck.in",
                                     const std::vector<std::string>& overrides = {}) {
  return errors_of([&] { parse_deck_string(text, path, overrides); });
}

// The messages of the InputError that setting up the deck's simulation throws.
std::vector<std::string> start_errors(const std::string& text, const std::string& path = "deck.in",
                                      const std::vector<std::string>& overrides = {}) {
  const Scene scene = parse_deck_string(text, path, overrides);
  return errors_of([&] { const Simulation sim(scene); });
}

::testing::AssertionResult has_message(const std::vector<std::string>& messages,
                                       const std::string& expected) {
  for (const auto& m : messages) {
    if (m == expected) return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "no message\n  " << expected << "\namong\n  "
                                       << fmt::format("{}", fmt::join(messages, "\n  "));
}

// The 1-based line of the deck that holds `text`.
int line_of(const std::string& deck, const std::string& text) {
  const std::size_t at = deck.find(text);
  EXPECT_NE(at, std::string::npos) << text;
  return 1 + static_cast<int>(std::count(deck.begin(), deck.begin() + static_cast<long>(at), '\n'));
}

const std::string kSteel = R"([[material]]
name = "steel"
density = 7800.0
youngs_modulus = 2.0e11
)";

const std::string kDrum = kSteel + R"(
[drum]
radius = 1.0
material = "steel"
)";

// Four bars 0.3 m high and 0.2 m wide; bar 0 points down from the axis, bar 1 to the right.
const std::string kLifters = R"(
[[drum.lifter]]
count = 4
height = 0.3
width = 0.2
angle = -90.0
)";

std::string particle(const std::string& position, double radius = 0.1,
                     const std::string& extra = "") {
  return fmt::format("\n[[particle]]\nmaterial = \"steel\"\nradius = {}\nposition = {}\n{}", radius,
                     position, extra);
}

// ---------------------------------------------------------------------------------------------
// Placement of file rows and lifters (placement.cpp)

// The rows of a [[fill]] file are placed like [[particle]] tables: a row outside the drum,
// overlapping the shell by more than 5 % of its radius, coinciding with a [[particle]] or
// overlapping an earlier row by more than 5 % of the smaller radius is refused at its CSV line,
// naming the fill's file key; a resting 0.5 % overlap passes.
TEST(Validation, CsvRowsArePlacedLikeParticles) {
  const TempDir dir;
  const std::string csv = dir.write("rows.csv",
                                    "x,y,radius\n"
                                    "0.3,-0.5,0.1\n"
                                    "0.0,3.0,0.1\n"
                                    "0.0,-0.95,0.1\n"
                                    "0.0,-0.5,0.1\n"
                                    "0.45,-0.5,0.1\n"
                                    "-0.3,-0.3,0.1\n"
                                    "-0.3,-0.1,0.1005\n");
  const std::string deck =
      kDrum + particle("[0.0, -0.5]") + "\n[[fill]]\nfile = \"rows.csv\"\nmaterial = \"steel\"\n";
  const auto messages = deck_errors(deck, dir.file("deck.in"));
  const auto row = [&](int line, const std::string& position) {
    return fmt::format("{}:{}: error: fill[0].file row: position = {}: ", csv, line, position);
  };
  EXPECT_TRUE(has_message(messages, row(3, "[0, 3]") +
                                        "the particle (radius 0.1 m) lies outside the drum "
                                        "(radius 1 m about [0, 0]); place it at least its radius "
                                        "inside the shell"));
  EXPECT_TRUE(has_message(messages, row(4, "[0, -0.95]") +
                                        "the particle (radius 0.1 m) overlaps the shell of the "
                                        "drum (radius 1 m about [0, 0]) by 50 % of its radius; at "
                                        "most 5 % is allowed at the start"));
  EXPECT_TRUE(has_message(
      messages, row(5, "[0, -0.5]") + fmt::format("coincides with particle[0] (line {}); give "
                                                  "each particle its own place",
                                                  line_of(deck, "[[particle]]"))));
  EXPECT_TRUE(has_message(messages, row(6, "[0.45, -0.5]") + "overlaps " + csv +
                                        ":2 by 50 % of the smaller radius; at most 5 % is "
                                        "allowed at the start"));
  EXPECT_EQ(messages.size(), 4u) << fmt::format("{}", fmt::join(messages, "\n"));
}

// A file shifted out of the drum as a whole gives kMaxCsvErrors messages and a count of the rest.
TEST(Validation, MisplacedRowsOfOneFileAreCapped) {
  const TempDir dir;
  std::string rows = "x,y,radius\n";
  for (int k = 0; k < 25; ++k) rows += fmt::format("{},5.0,0.1\n", 0.3 * k);
  const std::string csv = dir.write("far.csv", rows);
  const auto messages = deck_errors(
      kDrum + "\n[[fill]]\nfile = \"far.csv\"\nmaterial = \"steel\"\n", dir.file("deck.in"));
  ASSERT_EQ(messages.size(), 21u);
  EXPECT_EQ(
      messages[0].rfind(csv + ":2: error: fill[0].file row: position = [0, 5]: the particle", 0),
      0u)
      << messages[0];
  EXPECT_EQ(messages[19].rfind(csv + ":21: error: ", 0), 0u) << messages[19];
  EXPECT_EQ(messages[20], csv + ": error: 5 more misplaced rows in this file not shown");
}

// A particle inside a lifter bar, or reaching into one by more than 5 % of its radius, is refused
// naming the bar; one clear of the bars (0.05 m from the side of bar 1) passes. The bars turn
// with drum.angle.
TEST(Validation, NoParticleStartsInALifter) {
  const std::string deck = kDrum + kLifters + particle("[0.0, -0.85]", 0.05) +
                           particle("[0.0, -0.55]") + particle("[0.8, 0.25]") +
                           particle("[0.8, -0.17]");
  const auto messages = deck_errors(deck);
  const auto at = [&](const std::string& position) {
    return fmt::format("deck.in:{}:12: error: ", line_of(deck, "position = " + position));
  };
  EXPECT_TRUE(has_message(messages, at("[0.0, -0.85]") +
                                        "particle[0].position = [0.0, -0.85]: the particle "
                                        "(radius 0.05 m) lies inside bar 0 of drum.lifter[0] (the "
                                        "bars at the drum's initial angle); place it clear of the "
                                        "lifters"));
  EXPECT_TRUE(has_message(messages, at("[0.8, -0.17]") +
                                        "particle[3].position = [0.8, -0.17]: the particle "
                                        "(radius 0.1 m) overlaps bar 1 of drum.lifter[0] (the bars "
                                        "at the drum's initial angle) by 30 % of its radius; at "
                                        "most 5 % is allowed at the start"));
  EXPECT_EQ(messages.size(), 2u) << fmt::format("{}", fmt::join(messages, "\n"));

  // drum.angle = 90 turns a single bar at -90 degrees from pointing down to pointing right.
  const std::string turned =
      kSteel + "\n[drum]\nradius = 1.0\nmaterial = \"steel\"\nangle = 90.0\n" +
      "\n[[drum.lifter]]\ncount = 1\nheight = 0.3\nwidth = 0.2\nangle = -90.0\n" +
      particle("[0.85, 0.0]", 0.05) + particle("[0.0, -0.85]", 0.05);
  const auto turned_messages = deck_errors(turned);
  ASSERT_EQ(turned_messages.size(), 1u) << fmt::format("{}", fmt::join(turned_messages, "\n"));
  EXPECT_NE(turned_messages[0].find("particle[0].position = [0.85, 0.0]: the particle (radius "
                                    "0.05 m) lies inside bar 0 of drum.lifter[0]"),
            std::string::npos)
      << turned_messages[0];
}

TEST(Validation, CsvRowsKeepClearOfLifters) {
  const TempDir dir;
  const std::string csv = dir.write("rows.csv", "x,y,radius\n0.0,-0.5,0.05\n0.0,-0.85,0.05\n");
  const auto messages =
      deck_errors(kDrum + kLifters + "\n[[fill]]\nfile = \"rows.csv\"\nmaterial = \"steel\"\n",
                  dir.file("deck.in"));
  ASSERT_EQ(messages.size(), 1u) << fmt::format("{}", fmt::join(messages, "\n"));
  EXPECT_EQ(messages[0], csv +
                             ":3: error: fill[0].file row: position = [0, -0.85]: the particle "
                             "(radius 0.05 m) lies inside bar 0 of drum.lifter[0] (the bars at "
                             "the drum's initial angle); place it clear of the lifters");
}

// One tolerance for pairs, the shell and the bars (placement.hpp, Placement::kPlacementOverlap): a
// row overlapping the shell or a bar by 0.4 % of its radius passes, one overlapping it by 10 % is
// refused at its CSV line with the overlap and the 5 % allowed.
TEST(Validation, ShellAndBarsTakeTheOverlapAllowedBetweenParticles) {
  const TempDir dir;
  const std::string csv = dir.write("rows.csv",
                                    "x,y,radius\n"
                                    "0.54024,-0.72032,0.1\n"  // 0.9004 from the axis: 0.4 %
                                    "-0.546,-0.728,0.1\n"     // 0.91 from the axis: 10 %
                                    "0.8,-0.1996,0.1\n"       // 0.0996 from bar 1's side: 0.4 %
                                    "0.8,0.19,0.1\n"          // 0.09 from its other side: 10 %
                                    "0.0,-0.6004,0.1\n");     // on bar 0's top face: 0.4 %
  const auto messages =
      deck_errors(kDrum + kLifters + "\n[[fill]]\nfile = \"rows.csv\"\nmaterial = \"steel\"\n",
                  dir.file("deck.in"));
  EXPECT_TRUE(has_message(messages, csv +
                                        ":3: error: fill[0].file row: position = [-0.546, -0.728]: "
                                        "the particle (radius 0.1 m) overlaps the shell of the "
                                        "drum (radius 1 m about [0, 0]) by 10 % of its radius; at "
                                        "most 5 % is allowed at the start"));
  EXPECT_TRUE(has_message(messages, csv +
                                        ":5: error: fill[0].file row: position = [0.8, 0.19]: "
                                        "the particle (radius 0.1 m) overlaps bar 1 of "
                                        "drum.lifter[0] (the bars at the drum's initial angle) by "
                                        "10 % of its radius; at most 5 % is allowed at the start"));
  EXPECT_EQ(messages.size(), 2u) << fmt::format("{}", fmt::join(messages, "\n"));
}

// The same for a polygonal shell, measured from the nearest side: in a hexagon (apothem
// 0.866 m, a side facing down) a particle 0.0996 m from the bottom side passes, one 0.091 m from
// it is refused.
TEST(Validation, APolygonShellTakesTheSameTolerance) {
  const std::string deck = kSteel + "\n[drum]\nradius = 1.0\nsides = 6\nmaterial = \"steel\"\n" +
                           particle("[-0.3, -0.7664]") + particle("[0.3, -0.775]");
  const auto messages = deck_errors(deck);
  ASSERT_EQ(messages.size(), 1u) << fmt::format("{}", fmt::join(messages, "\n"));
  EXPECT_EQ(messages[0], fmt::format("deck.in:{}:12: error: particle[1].position = [0.3, -0.775]: "
                                     "the particle (radius 0.1 m) overlaps the shell of the drum "
                                     "(radius 1 m about [0, 0], 6 sides) by 8.97 % of its radius; "
                                     "at most 5 % is allowed at the start",
                                     line_of(deck, "position = [0.3, -0.775]")));
}

// A bed settled by dem2d itself and saved as x, y, radius, material rows is read back whole as a
// [[fill]] file, although the balls resting on the shell overlap it (Hertz contacts under the
// bed's weight), and the run starts from it: the containment check at the rebuilds passes.
// 200 balls of 8 mm in a 0.2 m drum, of a steel 100 times softer (a dt 6 times longer: settled
// in about 0.3 s simulated, under a second of CPU; the overlaps 20 times deeper, 0.2 % of a
// radius on the shell, still far within the 5 %).
TEST(Validation, ABedSettledByDem2dIsReadBackWhole) {
  const TempDir dir;
  const std::string drum = R"([[material]]
name = "ball"
density = 7800.0
youngs_modulus = 2.0e9
restitution = 0.2
sliding_friction = 0.5

[drum]
radius = 0.2
material = "ball"
)";
  Simulation settling(parse_deck_string(
      drum + "\n[[fill]]\nmaterial = \"ball\"\ncount = 200\nradius = 0.008\nregion = \"bottom\"\n",
      dir.file("settle.in")));
  const ParticleStore& p = settling.particles();
  const auto mean_speed = [&p] {
    double v2 = 0.0;
    for (std::size_t k = 0; k < p.n_owned(); ++k) v2 += norm2(p.vel[k]);
    return std::sqrt(v2 / static_cast<double>(p.n_owned()));
  };
  // At rest: a mean speed under 1 mm/s, looked at every 1000 steps, after at least 0.1 s.
  while (settling.time() < 0.1 || mean_speed() > 1.0e-3) {
    ASSERT_LT(settling.time(), 2.0) << "not at rest: mean speed " << mean_speed() << " m/s";
    for (int k = 0; k < 1000; ++k) settling.step();
  }
  std::string rows = "x,y,radius,material\n";
  double deepest = 0.0;  // the largest overlap with the shell, over the radius
  int on_shell = 0;
  for (std::size_t k = 0; k < p.n_owned(); ++k) {
    rows += fmt::format("{:.17g},{:.17g},{:.17g},ball\n", p.pos[k].x, p.pos[k].y, p.radius[k]);
    const double overlap = norm(p.pos[k]) + p.radius[k] - 0.2;
    if (overlap > 0.0) ++on_shell;
    deepest = std::max(deepest, overlap / p.radius[k]);
  }
  dir.write("bed.csv", rows);
  std::cout << "settled at t = " << settling.time() << " s: " << on_shell
            << " balls on the shell, overlapping it by up to " << 100.0 * deepest
            << " % of their radius\n";
  EXPECT_GT(on_shell, 0);  // the bed rests on the shell: without the tolerance it is refused

  Scene bed;
  ASSERT_NO_THROW(
      bed = parse_deck_string(drum + "\n[[fill]]\nfile = \"bed.csv\"\n", dir.file("deck.in")));
  ASSERT_EQ(bed.particles.size(), 200u);
  Simulation run(bed);
  EXPECT_NO_THROW(for (int k = 0; k < 2000; ++k) run.step());
  EXPECT_GT(run.neighbor_builds(), 1);  // the containment check ran
}

// Fills are placed clear of the lifter bars, also where a bar is wider than a lattice site, so
// that a site inside it is far from its sides.
TEST(Validation, FillsKeepOutOfLifterBars) {
  Scene s = parse_deck_string(kSteel + R"(
[drum]
radius = 2.0
material = "steel"

[[drum.lifter]]
count = 4
height = 0.6
width = 0.8

[[fill]]
material = "steel"
count = 400
radius = 0.03
region = "full"
)",
                              "deck.in");
  const Walls walls(s);
  ParticleStore p;
  place_particles(s, walls, p);
  ASSERT_EQ(p.size(), 400u);
  for (std::size_t k = 0; k < p.size(); ++k)
    EXPECT_FALSE(DrumGeometry(s.drum).bar_overlap(p.pos[k], p.radius[k])) << "particle " << k;
}

// The feed's point must hold a particle of radius_max inside the shell and clear of the bars.
TEST(Validation, FeedPointInsideTheDrum) {
  const std::string feed = R"(
[feed]
material = "steel"
period = 0.5
radius_min = 0.03
radius_max = 0.05
point = )";
  const std::string base = kDrum + kLifters + particle("[0.0, 0.0]");
  const auto outside = deck_errors(base + feed + "[0.0, 2.0]\n");
  ASSERT_EQ(outside.size(), 1u);
  EXPECT_EQ(outside[0], fmt::format("deck.in:{}:9: error: feed.point = [0.0, 2.0]: a fed particle "
                                    "of radius_max 0.05 m lies outside the drum (radius 1 m about "
                                    "[0, 0]); give a point at least radius_max inside the shell",
                                    line_of(base + feed, "point = ")));
  const auto in_bar = deck_errors(base + feed + "[0.0, -0.85]\n");
  ASSERT_EQ(in_bar.size(), 1u);
  EXPECT_NE(in_bar[0].find("feed.point = [0.0, -0.85]: a fed particle of radius_max 0.05 m lies "
                           "inside bar 0 of drum.lifter[0]; give a point clear of the lifters"),
            std::string::npos)
      << in_bar[0];
}

// An empty file, or one with a header and no rows, is named at the deck's file key.
TEST(Validation, WholeFileProblemsAtTheFileKey) {
  const TempDir dir;
  dir.write("empty.csv", "");
  dir.write("header.csv", "x,y,radius\n");
  const std::string deck = kDrum + "\n[[fill]]\nfile = \"empty.csv\"\nmaterial = \"steel\"\n" +
                           "\n[[fill]]\nfile = \"header.csv\"\nmaterial = \"steel\"\n";
  const std::string path = dir.file("deck.in");
  const auto messages = deck_errors(deck, path);
  EXPECT_TRUE(
      has_message(messages, fmt::format("{}:{}:8: error: fill[0].file = \"empty.csv\": "
                                        "{} is empty: expected a header row naming x, y, "
                                        "radius",
                                        path, line_of(deck, "empty.csv"), dir.file("empty.csv"))));
  EXPECT_TRUE(has_message(messages,
                          fmt::format("{}:{}:8: error: fill[1].file = \"header.csv\": "
                                      "{} has a header row but no rows: no particles",
                                      path, line_of(deck, "header.csv"), dir.file("header.csv"))));
  EXPECT_EQ(messages.size(), 2u);
}

// The deck records where it set the values that later checks may refuse.
TEST(Validation, TheSceneKnowsWhereItsKeysWereSet) {
  const TempDir dir;
  dir.write("rows.csv", "x,y,radius\n0.0,-0.5,0.1\n");
  const std::string deck = "[run]\nduration = 2.0\n" + kDrum + particle("[0.3, -0.5]") +
                           "\n[[fill]]\nmaterial = \"steel\"\ncount = 5\nradius = 0.05\n" +
                           "\n[[fill]]\nfile = \"rows.csv\"\nmaterial = \"steel\"\n";
  const std::string path = dir.file("deck.in");
  const Scene s = parse_deck_string(deck, path, {"particle.0.velocity=[1, 0]"});
  EXPECT_EQ(s.where.at("run.duration"), path + ":2:12");
  EXPECT_EQ(s.where.at("particle[0].velocity"), "--set particle.0.velocity=[1, 0]");
  EXPECT_EQ(s.where.at("fill[0].count"), fmt::format("{}:{}:9", path, line_of(deck, "count = 5")));
  EXPECT_EQ(s.where.at("fill[1].file"), fmt::format("{}:{}:8", path, line_of(deck, "rows.csv")));
  EXPECT_EQ(s.where.at("fill[1].csv"), dir.file("rows.csv"));
  EXPECT_FALSE(s.where.contains("fill[0].velocity"));  // a default is set nowhere
  ASSERT_EQ(s.fills.size(), 1u);
  EXPECT_EQ(s.fills[0].index, 0);
  ASSERT_EQ(s.file_fills.size(), 1u);
  EXPECT_EQ(s.file_fills[0].index, 1);
}

// ---------------------------------------------------------------------------------------------
// The first step, the step count, the memory (validate.cpp)

// At dt = 1e-4 s a particle of radius 0.1 m may move 250 m/s (a quarter radius per step). Faster
// initial velocities, spins, fills, file rows and walls are refused at their keys (a file fill's
// velocity at the fill for rows without vx, vy; a row's own at its line); 200 m/s passes.
TEST(Validation, NothingMovesMoreThanAQuarterRadiusInTheFirstStep) {
  const TempDir dir;
  dir.write("slow.csv", "x,y,radius\n3.0,0.0,0.1\n");
  const std::string fast = dir.write("fast.csv",
                                     "x,y,radius,vx,vy\n4.0,0.0,0.1,0.0,0.0\n"
                                     "4.5,0.0,0.1,300.0,0.0\n");
  const std::string deck = R"([run]
dt = 1.0e-4
allow_unsafe_dt = true
gravity = [0.0, 0.0]
)" + kSteel + particle("[0.0, 0.0]", 0.1, "velocity = [200.0, 0.0]\n") +
                           particle("[1.0, 0.0]", 0.1, "velocity = [0.0, -300.0]\n") +
                           particle("[2.0, 0.0]", 0.1, "spin = 3000.0\n") + R"(
[[wall]]
from = [-5.0, -1.0]
to = [5.0, -1.0]
material = "steel"
velocity = [0.0, 300.0]

[[fill]]
material = "steel"
count = 3
radius = 0.1
region = "box"
box_min = [-1.0, 2.0]
box_max = [1.0, 3.0]
velocity = [300.0, 0.0]

[[fill]]
file = "slow.csv"
material = "steel"
velocity = [0.0, 300.0]

[[fill]]
file = "fast.csv"
material = "steel"
)";
  const std::string path = dir.file("deck.in");
  const auto messages = start_errors(deck, path);
  const std::string step =
      " in the first step at dt = 0.0001 s (run.dt); at most 0.25 of a "
      "radius per step is allowed (here a speed up to 250 m/s), or bodies "
      "could pass through each other";
  const auto at = [&](const std::string& text, int column) {
    return fmt::format("{}:{}:{}: error: ", path, line_of(deck, text), column);
  };
  EXPECT_TRUE(has_message(messages, at("velocity = [0.0, -300.0]", 12) +
                                        "particle[1].velocity = [0, -300] m/s: the particle would "
                                        "move 0.3 times its radius (0.1 m)" +
                                        step));
  EXPECT_TRUE(has_message(messages, at("spin = 3000.0", 8) +
                                        "particle[2].spin = 3000 rad/s: the particle's surface "
                                        "would move 0.3 times its radius in the first step at dt "
                                        "= 0.0001 s (run.dt); at most 0.25 of a radius per step "
                                        "is allowed (here a spin up to 2.5e+03 rad/s)"));
  EXPECT_TRUE(has_message(messages, at("velocity = [300.0, 0.0]", 12) +
                                        "fill[0].velocity = [300, 0] m/s: a particle of the fill "
                                        "would move 0.3 times its radius (0.1 m)" +
                                        step));
  EXPECT_TRUE(has_message(messages, at("velocity = [0.0, 300.0]\n\n[[fill]]\nfile = \"fast", 12) +
                                        "fill[1].velocity = [0, 300] m/s: a particle of the fill "
                                        "would move 0.3 times its radius (0.1 m)" +
                                        step));
  EXPECT_TRUE(has_message(messages, fast +
                                        ":3: error: fill[2].file row: velocity = [300, 0] "
                                        "m/s: the particle would move 0.3 times its radius "
                                        "(0.1 m)" +
                                        step));
  EXPECT_TRUE(has_message(
      messages, at("velocity = [0.0, 300.0]", 12) +
                    "wall[0].velocity = [0, 300] m/s: the wall would move 0.3 times the smallest "
                    "particle's radius (0.1 m) in one step at dt = 0.0001 s (run.dt); at most 0.25 "
                    "of a radius per step is allowed (here a speed up to 250 m/s), or bodies could "
                    "pass through each other"));
  EXPECT_EQ(messages.size(), 6u) << fmt::format("{}", fmt::join(messages, "\n"));
}

// The drum's rim and the fed particles move a quarter radius per step at most; a key that an
// override set is named by the option.
TEST(Validation, DrumAndFeedSpeedsAreBounded) {
  const std::string deck = R"([run]
dt = 1.0e-4
allow_unsafe_dt = true
)" + kDrum + "speed = 260.0\n" +
                           particle("[0.0, -0.5]") + R"(
[feed]
material = "steel"
period = 0.5
radius_min = 0.1
radius_max = 0.1
velocity = [0.0, -260.0]
)";
  const auto messages = start_errors(deck);
  EXPECT_TRUE(has_message(messages, fmt::format("deck.in:{}:9: error: drum.speed = 260 rad/s: the "
                                                "shell (rim speed 260 m/s) would move 0.26 times "
                                                "the smallest particle's radius (0.1 m) in one "
                                                "step at dt = 0.0001 s (run.dt); at most 0.25 of a "
                                                "radius per step is allowed (here a speed up to "
                                                "250 m/s), or bodies could pass through each other",
                                                line_of(deck, "speed = 260"))));
  EXPECT_TRUE(has_message(messages, fmt::format("deck.in:{}:12: error: feed.velocity = [0, -260] "
                                                "m/s: a fed particle would move 0.26 times its "
                                                "radius (0.1 m) in the first step at dt = 0.0001 s "
                                                "(run.dt); at most 0.25 of a radius per step is "
                                                "allowed (here a speed up to 250 m/s), or bodies "
                                                "could pass through each other",
                                                line_of(deck, "velocity = [0.0, -260.0]"))));
  EXPECT_EQ(messages.size(), 2u) << fmt::format("{}", fmt::join(messages, "\n"));

  const auto rpm = start_errors(kDrum + "speed_rpm = 2500.0\n" + particle("[0.0, -0.5]"), "deck.in",
                                {"run.dt=1e-4", "run.allow_unsafe_dt=true"});
  ASSERT_EQ(rpm.size(), 1u);
  EXPECT_EQ(rpm[0].rfind(fmt::format("deck.in:9:13: error: drum.speed_rpm gives 261.799 rad/s: "
                                     "the shell (rim speed 262 m/s) would move 0.262 times")),
            0u)
      << rpm[0];
  const auto set =
      start_errors(kDrum + particle("[0.0, -0.5]"), "deck.in", {"particle.0.velocity=[0, 1e6]"});
  ASSERT_EQ(set.size(), 1u);
  EXPECT_EQ(set[0].rfind("--set particle.0.velocity=[0, 1e6]: error: particle[0].velocity = [0, "
                         "1e+06] m/s: the particle would move ",
                         0),
            0u)
      << set[0];
}

// A run of more than kMaxRunSteps steps is refused at run.duration with the step count and
// the dt; 5e11 steps are accepted.
TEST(Validation, AtMostATrillionSteps) {
  const std::string deck =
      "[run]\nduration = 2.0e6\ndt = 1.0e-6\n" + kSteel + particle("[0.0, 0.0]");
  const auto messages = start_errors(deck);
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0],
            "deck.in:2:12: error: run.duration = 2e+06 s is 2e+12 steps of dt = 1e-06 "
            "s (run.dt); at most 1e+12 steps are allowed (days of wall time at the "
            "fastest a step goes): shorten the duration, or give a larger run.dt");
  EXPECT_NO_THROW(Simulation(parse_deck_string(deck, "deck.in", {"run.duration=5e5"})));
  const auto forever =
      start_errors(kSteel + particle("[0.0, 0.0]"), "deck.in", {"run.duration=1e300"});
  ASSERT_EQ(forever.size(), 1u);
  EXPECT_EQ(forever[0].rfind("--set run.duration=1e300: error: run.duration = 1e+300 s is ", 0), 0u)
      << forever[0];
  EXPECT_NE(forever[0].find("(dt = \"auto\"); at most 1e+12 steps are allowed (days of wall time "
                            "at the fastest a step goes): shorten the duration"),
            std::string::npos)
      << forever[0];
}

// The memory the particles need, checked before any is placed: the largest fill's count key is
// named with the estimate and the memory available.
TEST(Validation, MemoryIsEstimatedBeforePlacing) {
  const std::string deck =
      kDrum + "\n[[fill]]\nmaterial = \"steel\"\ncount = 10000\nradius = 0.005\n";
  const Scene s = parse_deck_string(deck, "deck.in");
  const double bytes = particle_memory_bytes(s, 10000.0);
  EXPECT_DOUBLE_EQ(particle_memory_bytes(s, 20000.0), 2.0 * bytes);
  EXPECT_GT(bytes, 10000.0 * 2.0 * static_cast<double>(ParticleStore().bytes_per_particle()));
  EXPECT_NO_THROW(check_memory(s, 1.0e12));
  const auto messages = errors_of([&] { check_memory(s, 1024.0 * 1024.0); });
  ASSERT_EQ(messages.size(), 1u);
  const std::string& m = messages[0];
  EXPECT_EQ(m.rfind(fmt::format("deck.in:{}:9: error: fill[0].count = 10000: the particles at the "
                                "start (1e+04 in all, about ",
                                line_of(deck, "count = ")),
                    0),
            0u)
      << m;
  EXPECT_NE(m.find(" GiB of memory, more than this machine's 0.000977 GiB; place fewer particles "
                   "or larger ones"),
            std::string::npos)
      << m;

  // Through the simulation, with the machine's memory: 1e12 particles are refused at once.
  const auto huge = start_errors(kDrum +
                                 "\n[[fill]]\nmaterial = \"steel\"\ncount = "
                                 "1000000000000\nradius = 0.001\n");
  ASSERT_EQ(huge.size(), 1u);
  EXPECT_EQ(huge[0].rfind("deck.in:12:9: error: fill[0].count = 1000000000000: the particles at "
                          "the start (1e+12 in all",
                          0),
            0u)
      << huge[0];
}

// A fill_fraction's count is estimated without drawing the radii (within a few % of the count
// drawn); a tiny radius in a large box makes a lattice no memory holds, named at the radius.
TEST(Validation, FillFractionsAndLatticesAreEstimated) {
  const Scene s = parse_deck_string(kDrum + R"(
[[fill]]
material = "steel"
fill_fraction = 0.3
radius_min = 0.01
radius_max = 0.03
)",
                                    "deck.in");
  const double expected = expected_fill_count(s, 0);
  EXPECT_NEAR(expected, static_cast<double>(fill_count(s, 0)), 0.05 * expected);
  const std::string box = kSteel + R"(
[[fill]]
material = "steel"
count = 10
radius = 1.0e-6
region = "box"
box_min = [-100.0, -100.0]
box_max = [100.0, 100.0]
)";
  const Scene lattice = parse_deck_string(box, "deck.in");
  EXPECT_GT(fill_lattice_sites(lattice, 0), 1.0e15);
  const auto messages = errors_of([&] { check_memory(lattice, 16.0 * 1024 * 1024 * 1024); });
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0].rfind(fmt::format("deck.in:{}:10: error: fill[0].radius = 1e-06: placing "
                                          "the fill lays a lattice of 1.05e+16 sites",
                                          line_of(box, "radius = ")),
                              0),
            0u)
      << messages[0];
}

}  // namespace
}  // namespace dem2d
