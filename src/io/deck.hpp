// Deck: the TOML input deck (docs/input.md) read into a validated Scene, and a Scene written
// back as a resolved deck (every default filled in) in TOML or JSON.
//
// Reading is all-or-nothing: every error in the deck, in the --set overrides and in the CSV
// packings it names is collected, then one InputError holds them all, each formatted as
//   FILE:LINE:COL: error: MESSAGE     (a deck value, key or table with a known position)
//   FILE: error: MESSAGE              (no position: the deck as a whole, or a --set table)
//   CSVFILE:LINE: error: MESSAGE      (a row of a [[fill]] file)
//   --set KEY=VALUE: error: MESSAGE   (a value or key that a --set override put there)
// A message names the key by its full dotted path (material[1].youngs_modulus), the bad value
// and what is allowed; an unknown key is matched against the valid ones by edit distance.
#pragma once

#include <numbers>
#include <string>
#include <vector>

#include "core/base/scene.hpp"

namespace dem2d {

// Unit conversions of the deck (angles in degrees where a person types them, rpm for speeds).
inline constexpr double kRadiansPerDegree = std::numbers::pi / 180.0;         // rad = deg * k
inline constexpr double kRadPerSecondPerRpm = 2.0 * std::numbers::pi / 60.0;  // rad/s = rpm * k

// Reads, overrides, validates and resolves the deck at `path`. `overrides` are the values of
// the command line's "--set KEY=VALUE" options, applied in order to the TOML tree before
// validation. KEY is a dotted path; an element of an array of tables is selected by index or,
// for [[material]], by name: "drum.speed=1.5", "run.dt=auto", "material.steel.restitution=0.5",
// "material.0.restitution=0.5", "fill.1.count=100", "drum.lifter.0.height=0.1". VALUE is a
// TOML value ("1.5", "true", "[0.0, -9.81]", "'text'"), or else taken as a bare string.
// Throws InputError holding every error found.
Scene load_deck(const std::string& path, const std::vector<std::string>& overrides = {});

// The same, for deck text already in memory. `path_for_messages` names the deck in messages
// and its directory is where relative [[fill]] file paths are looked up.
Scene parse_deck_string(const std::string& text, const std::string& path_for_messages,
                        const std::vector<std::string>& overrides = {});

// The scene as a deck with every default filled in, in the order of docs/input.md, which
// load_deck reads back to the same values: angles in degrees (chosen so that they convert back
// to the same radians bit for bit), the drum speed in rad/s, dt = "auto" or a number, file
// fills by their absolute path, and the shear modulus or Poisson's ratio, whichever reproduces
// both exactly.
std::string resolved_deck_toml(const Scene& scene);

// The same resolved deck as one JSON object (tables are objects, arrays of tables are arrays
// of objects), indented by two spaces; used in run.json.
std::string resolved_deck_json(const Scene& scene);

}  // namespace dem2d
