// The files a run appends to as it goes, seen from every rank: series.csv, product.csv with
// breakages.csv of ore scenes, and lifters.csv of drums with lifters. Rank 0 alone writes;
// every write is agreed on, so a failure there (disk full) stops every rank with the same
// message (IoError, exit 4) instead of leaving the others in a collective.
#pragma once

#include <memory>
#include <optional>

#include "core/geometry/lifter_loads.hpp"
#include "core/run/simulation.hpp"
#include "core/structure/shell.hpp"
#include "io/lifter_log.hpp"
#include "io/ore_logs.hpp"
#include "io/series.hpp"

namespace dem2d {

// series.csv.
class SeriesOutput {
 public:
  // Collective. `resumed`: a restart, which continues the file after the checkpoint's step.
  SeriesOutput(const Scene& scene, const Simulation& sim, bool resumed);
  void write(const SeriesRow& row);  // collective

 private:
  std::unique_ptr<SeriesWriter> file_;
};

// product.csv and breakages.csv of ore scenes (nothing for other scenes): every rank's records
// since the last write are gathered (parallel/ore_records.hpp) and rank 0 appends them.
class OreOutput {
 public:
  // Collective. `resumed`: a restart, which keeps the rows up to the checkpoint's time.
  OreOutput(const Scene& scene, const Simulation& sim, bool resumed);
  void write(Simulation& sim);  // collective: takes the simulation's records

 private:
  std::unique_ptr<OreLogs> logs_;
};

// lifters.csv of drum scenes with lifter bars (nothing for other scenes): at a series row, the
// last force evaluation's records on the bars, resolved on their ranks, gathered (6 words per
// record), merged in (particle id, element) order and summed per bar in that order, the same
// bits on any rank count; rank 0 appends one row per bar. With a [shell], the records on the
// shell and the bars are gathered in the same order (6 words each: id, element, point, force)
// and rank 0 solves the shell's response to them (core/structure/shell.hpp) for the row's shell
// columns.
class LifterOutput {
 public:
  // Collective. `resumed`: a restart, which keeps the rows up to the checkpoint's time.
  LifterOutput(const Scene& scene, const Simulation& sim, bool resumed);
  ~LifterOutput();
  void write(const Simulation& sim);  // collective
  // The shell's model on rank 0 (null elsewhere and without a [shell]).
  const Shell* shell() const { return shell_.get(); }
  // Collective: the shell's displacement and stress under the last force evaluation's wall
  // loads (gathered and solved as for a row), on rank 0; std::nullopt elsewhere and without a
  // [shell].
  std::optional<ShellField> shell_field(const Simulation& sim) const;
  // The shell's response at the last row written (rank 0).
  const ShellResponse& last_response() const { return response_; }

 private:
  std::unique_ptr<LifterBars> bars_;
  std::unique_ptr<LifterLog> log_;
  bool has_shell_ = false;
  std::unique_ptr<Shell> shell_;
  ShellResponse response_;
};

}  // namespace dem2d
