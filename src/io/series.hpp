// SeriesWriter: series.csv, one row of global diagnostics per series interval.
//
// The columns are described once, in kSeriesColumns: name, unit, meaning and the SeriesRow
// member that holds the value. The header, every row and the column table of docs/output.md
// come from it (SeriesDocs.ColumnsMatchTheTable fails when the docs differ). Doubles are
// written with %.17g, so strtod reads back the exact bits; integers as integers. Each row is
// flushed, so a crash loses nothing already written. Only the active writer (rank 0) touches
// the file; the others do nothing.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "core/diagnostics.hpp"

namespace dem2d {

// One column of series.csv.
struct SeriesColumn {
  std::string_view name;
  std::string_view unit;  // "" in the docs: "–"
  std::variant<double SeriesRow::*, std::int64_t SeriesRow::*> value;
  bool iterative_only = false;  // written only with the iterative integrator
  std::string_view doc;         // the docs' "meaning" column (Markdown)
};

// The columns, in order (docs/output.md; the energy balance is explained there).
inline constexpr SeriesColumn kSeriesColumns[] = {
    {"time", "s", &SeriesRow::time, false, "simulated time of the row"},
    {"step", "", &SeriesRow::step, false, "time steps taken since the start of the run"},
    {"particles", "", &SeriesRow::particles, false, "particles in the system (all ranks)"},
    {"contacts", "", &SeriesRow::contacts, false,
     "particle–particle plus particle–wall (drum, lifter, wall segment) contacts"},
    {"kinetic_energy", "J", &SeriesRow::kinetic_energy, false, "Σ ½ m v²"},
    {"rotational_energy", "J", &SeriesRow::rotational_energy, false, "Σ ½ I ω², I = 2/5 m r²"},
    {"potential_energy", "J", &SeriesRow::potential_energy, false,
     "Σ −m g·x, zero at the origin (can be negative)"},
    {"elastic_energy", "J", &SeriesRow::elastic_energy, false,
     "energy stored in the contact springs now: normal, tangential, rolling"},
    {"dissipated_energy", "J", &SeriesRow::dissipated_energy, false,
     "cumulative energy lost since the start: normal and tangential damping, sliding "
     "friction, rolling resistance"},
    {"drum_torque", "N m", &SeriesRow::drum_torque, false,
     "torque the drive applies to the drum to keep its prescribed speed (counter-clockwise "
     "positive)"},
    {"drum_power", "W", &SeriesRow::drum_power, false,
     "`drum_torque` × drum angular speed: the drive's power"},
    {"drive_work", "J", &SeriesRow::drive_work, false,
     "cumulative work done on the particles by the drive (drum, lifters) and by moving walls"},
    {"passes", "", &SeriesRow::passes, true,
     "iterative integrator only: mean number of force passes per step since the previous row"},
};

// The column names of series.csv, in order ("passes" last, for the iterative integrator).
std::vector<std::string> series_columns(bool iterative);

// The column table of docs/output.md (between "<!-- columns: series.csv -->" and
// "<!-- end columns -->"): header, separator and one line per column, each ending in '\n'.
std::string series_columns_markdown();

class SeriesWriter {
 public:
  // Creates (truncating) `path` and writes the header row. Throws IoError
  // "cannot create PATH: REASON" when it cannot (active writer only).
  SeriesWriter(const std::string& path, bool iterative, bool active);
  ~SeriesWriter();  // flushes and closes; never throws
  SeriesWriter(const SeriesWriter&) = delete;
  SeriesWriter& operator=(const SeriesWriter&) = delete;

  // Appends one row and flushes it. Throws IoError "cannot write PATH: REASON".
  void write(const SeriesRow& row);

  const std::string& path() const { return path_; }

 private:
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  void put(const std::string& text);

  std::string path_;
  bool iterative_;
  std::unique_ptr<std::FILE, Closer> file_;
};

}  // namespace dem2d
