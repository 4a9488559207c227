// One fuzz input through the deck reader and the checks that follow it without MPI: what the
// fuzz target (fuzz_deck.cpp) runs on every input and the replay test
// (test_fuzz_regressions.cpp) runs on every kept finding (docs/fuzzing.md).
//
// An input is deck text, optionally followed by sections that each start on a marker line:
//   DECK TEXT
//   #--set            each following line is one --set override (KEY=VALUE)
//   drum.speed=2
//   #--csv            the rest is a [[fill]] CSV packing, read by read_particle_csv
//   x,y,radius
// The markers are TOML comments, so a deck without them is an ordinary deck.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace dem2d::fuzz {

inline constexpr std::string_view kSetMarker = "#--set";
inline constexpr std::string_view kCsvMarker = "#--csv";
// The deck's name in messages; its folder does not exist, so [[fill]] files given by a relative
// path are not found (absolute paths are read as dem2d would read them).
inline constexpr std::string_view kDeckPath = "fuzz-deck/deck.in";

struct FuzzCase {
  std::string deck;
  std::vector<std::string> overrides;
  std::optional<std::string> csv;
};

// The sections of an input (see above).
FuzzCase split_case(std::string_view data);

// Reads the CSV section (if any), then the deck with its overrides; for a deck that is read
// without error, the checks that follow without MPI and without placing the fills' particles
// (core/setup/validate.hpp, core/step/time_scales.hpp): how many particles each fill expects, the
// time scales and dt over the deck's particles and one particle of each fill's smallest radius, the
// checks of the first step at that dt, and the resolved deck, which must read back.
// Throws InputError for bad input (expected); anything else that escapes is a finding
// (std::logic_error when a resolved deck does not read back).
void exercise_deck(std::string_view data);

}  // namespace dem2d::fuzz
