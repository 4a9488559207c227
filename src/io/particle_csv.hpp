// Particle packings read from CSV files (a [[fill]] with `file`, docs/input.md).
//
// Format: a header row naming the columns, in any order and any case: x, y, radius (m,
// required), vx, vy (m/s), spin (rad/s), material (a [[material]] name) optional; then one
// particle per row. Fields are separated by commas and may be quoted as RFC 4180 says: a field
// in double quotes may hold commas, a doubled quote inside it is one quote; a quoted field ends
// on its line. Blank lines and lines starting with '#' are skipped.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/base/scene.hpp"

namespace dem2d {

// Values for the columns a file leaves out (and for an empty material field).
struct CsvDefaults {
  std::string material;  // "": every row must name its material
  Vec2 velocity{0.0, 0.0};
};

struct CsvPacking {
  std::vector<ParticleSpec> particles;  // source_line = the line in the file
  // Complete messages, "FILE:LINE: error: ..."; at most kMaxCsvErrors of them plus one line
  // "FILE: error: N more errors ..." counting the rest.
  std::vector<std::string> errors;
  // What is wrong with the file as a whole, to follow its name ("is empty: ..."): the deck
  // reports it at the key that named the file.
  std::vector<std::string> file_errors;
  bool has_material_column = false;
};

inline constexpr int kMaxCsvErrors = 20;

// Reads the text of one file; `shown` names it in messages, `material_names` are the deck's,
// `key` is the deck key that named the file ("fill[2].file"), which a message about a row or
// the header names after the location ("packing.csv:7: error: fill[2].file row: ...").
// Without a material column and without a default material, no row is read and no row error
// is given: the caller reports that the fill needs a material.
CsvPacking read_particle_csv(std::string_view text, const std::string& shown,
                             const std::vector<std::string>& material_names,
                             const CsvDefaults& defaults, std::string_view key = {});

}  // namespace dem2d
