// Placement: where the deck's own particles start (docs/input.md, "Placement"), checked by the
// deck reader after every [[particle]] and [[fill]] file has been read. Internal to the deck
// reader (deck.cpp).
#pragma once

#include <toml++/toml.h>

#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/base/scene.hpp"
#include "core/geometry/drum_geometry.hpp"
#include "io/deck_diagnostics.hpp"

namespace dem2d::deck {

// The particles that one [[fill]] file added to Scene::particles, and the file as messages
// name it.
struct FileRows {
  std::size_t first = 0;
  std::size_t count = 0;
  std::size_t fill = 0;  // the element of [[fill]]
  std::string shown;
  int reported = 0;  // messages about its rows so far
};

// Checks the particles the deck places itself, the [[particle]] tables and then the rows of the
// [[fill]] files (as Scene::particles holds them), before step 1: inside the drum, clear of the
// lifter bars, and apart from each other, each up to the one tolerance kPlacementOverlap. A
// particle that overlaps the drum's shell (circle or polygon) or a lifter bar by more than
// kPlacementOverlap of its radius, or another particle by more than kPlacementOverlap of the
// smaller radius, is bad input at its table's position, or at its CSV row (at most
// kMaxCsvErrors rows of a file, then a count of the others).
class Placement {
 public:
  // The overlap a particle may start with, as a fraction of its radius (of the smaller one for
  // a pair): the same for pairs, the shell and the lifter bars, so that a packing saved from a
  // settled run, by dem2d or another code, passes whole (a resting Hertz contact overlaps well
  // under 1 %: 200 steel balls of 8 mm settled by dem2d rest on the shell with at most 0.01 %).
  // The first step pushes such a contact apart like any other.
  static constexpr double kPlacementOverlap = 0.05;

  // `tables`: the [[particle]] tables, which hold the first particles of `scene`; `files`: the
  // rows of each [[fill]] file after them, in order.
  Placement(const Scene& scene, Diagnostics& diag, const std::vector<const toml::table*>& tables,
            std::vector<FileRows> files)
      : scene_(scene), drum_(scene.drum), diag_(diag), tables_(tables), files_(std::move(files)) {}

  // Every misplaced particle, into the Diagnostics.
  void check();

 private:
  bool in_drum(std::size_t i);
  void clear_of_lifters(std::size_t i);
  static std::string allowed();
  void check_pairs();
  double overlap(std::size_t i, std::size_t j) const;
  double smaller(std::size_t i, std::size_t j) const;
  void report_pair(std::size_t i, std::size_t j);
  FileRows& file_of(std::size_t i);
  std::string name(std::size_t i);
  void report(std::size_t i, std::string_view what);

  const Scene& scene_;
  DrumGeometry drum_;
  Diagnostics& diag_;
  const std::vector<const toml::table*>& tables_;
  std::vector<FileRows> files_;
};

}  // namespace dem2d::deck
