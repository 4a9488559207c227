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

#include "core/step/diagnostics.hpp"

namespace dem2d {

// Which runs write a column.
enum class SeriesOnly {
  kAlways,
  kIterative,  // the iterative integrator
  kOre,        // ore scenes: [breakage], [feed] or [sieve]
  kDrum,       // scenes with a [drum]: the mill analytics
};

// One column of series.csv.
struct SeriesColumn {
  std::string_view name;
  std::string_view unit;  // "" in the docs: "–"
  std::variant<double SeriesRow::*, std::int64_t SeriesRow::*, const char * SeriesRow::*> value;
  SeriesOnly only = SeriesOnly::kAlways;
  std::string_view doc;  // the docs' "meaning" column (Markdown)
};

// The columns, in order (docs/output.md; the energy balance is explained there).
inline constexpr SeriesColumn kSeriesColumns[] = {
    {"time", "s", &SeriesRow::time, SeriesOnly::kAlways, "simulated time of the row"},
    {"step", "", &SeriesRow::step, SeriesOnly::kAlways,
     "time steps taken since the start of the run"},
    {"particles", "", &SeriesRow::particles, SeriesOnly::kAlways,
     "particles in the system (all ranks)"},
    {"contacts", "", &SeriesRow::contacts, SeriesOnly::kAlways,
     "particle–particle plus particle–wall (drum, lifter, wall segment) contacts"},
    {"kinetic_energy", "J", &SeriesRow::kinetic_energy, SeriesOnly::kAlways, "Σ ½ m v²"},
    {"rotational_energy", "J", &SeriesRow::rotational_energy, SeriesOnly::kAlways,
     "Σ ½ I ω², I = 2/5 m r²"},
    {"potential_energy", "J", &SeriesRow::potential_energy, SeriesOnly::kAlways,
     "Σ −m g·x, zero at the origin (can be negative)"},
    {"elastic_energy", "J", &SeriesRow::elastic_energy, SeriesOnly::kAlways,
     "energy stored in the contact springs now: normal, tangential, rolling"},
    {"dissipated_energy", "J", &SeriesRow::dissipated_energy, SeriesOnly::kAlways,
     "cumulative energy lost since the start: normal and tangential damping, sliding "
     "friction, rolling resistance"},
    {"drum_torque", "N m", &SeriesRow::drum_torque, SeriesOnly::kAlways,
     "torque the drive applies to the drum to keep its prescribed speed (counter-clockwise "
     "positive)"},
    {"drum_power", "W", &SeriesRow::drum_power, SeriesOnly::kAlways,
     "`drum_torque` × drum angular speed: the drive's power"},
    {"drive_work", "J", &SeriesRow::drive_work, SeriesOnly::kAlways,
     "cumulative work done on the particles by the drive (drum, lifters) and by moving walls"},
    {"passes", "", &SeriesRow::passes, SeriesOnly::kIterative,
     "iterative integrator only: mean number of force passes per step since the previous row"},
    {"breakages", "", &SeriesRow::breakages, SeriesOnly::kOre,
     "ore scenes: particles broken since the start"},
    {"fragments", "", &SeriesRow::fragments, SeriesOnly::kOre,
     "ore scenes: fragments born since the start"},
    {"fed_count", "", &SeriesRow::fed_count, SeriesOnly::kOre,
     "ore scenes: particles fed since the start"},
    {"fed_mass", "kg", &SeriesRow::fed_mass, SeriesOnly::kOre,
     "ore scenes: mass fed since the start"},
    {"discharged_count", "", &SeriesRow::discharged_count, SeriesOnly::kOre,
     "ore scenes: particles the discharge let out since the start (`product.csv`)"},
    {"discharged_mass", "kg", &SeriesRow::discharged_mass, SeriesOnly::kOre,
     "ore scenes: their mass and the fines of t10 breaks (which leave at once); initial "
     "`mill_mass` + `fed_mass` = `mill_mass` + `discharged_mass` at every row"},
    {"mill_mass", "kg", &SeriesRow::mill_mass, SeriesOnly::kOre,
     "ore scenes: mass of every particle in the mill"},
    {"ore_mass", "kg", &SeriesRow::ore_mass, SeriesOnly::kOre,
     "ore scenes: mass of the ore in the mill (the breakage material, else the feed's)"},
    {"fed_energy", "J", &SeriesRow::fed_energy, SeriesOnly::kOre,
     "ore scenes: kinetic and potential energy the fed particles brought in (a term of the "
     "energy balance)"},
    {"discharged_energy", "J", &SeriesRow::discharged_energy, SeriesOnly::kOre,
     "ore scenes: kinetic, rotational and potential energy the discharged particles and the "
     "fines took out (a term of the energy balance)"},
    {"shell_torque", "N m", &SeriesRow::shell_torque, SeriesOnly::kDrum,
     "drum scenes: the part of `drum_torque` the shell's contacts take (`drum_torque` − "
     "`lifter_torque`)"},
    {"lifter_torque", "N m", &SeriesRow::lifter_torque, SeriesOnly::kDrum,
     "drum scenes: the part of `drum_torque` the lifters' contacts take (per bar: "
     "`lifters.csv`)"},
    {"shell_power", "W", &SeriesRow::shell_power, SeriesOnly::kDrum,
     "drum scenes: `shell_torque` × drum angular speed"},
    {"lifter_power", "W", &SeriesRow::lifter_power, SeriesOnly::kDrum,
     "drum scenes: `lifter_torque` × drum angular speed"},
    {"drum_work", "J", &SeriesRow::drum_work, SeriesOnly::kDrum,
     "drum scenes: cumulative work of the drum's drive (`drive_work` without moving walls)"},
    {"power_avg", "W", &SeriesRow::power_avg, SeriesOnly::kDrum,
     "drum scenes: the drive's mean power over the last `output.analysis_window` seconds: the "
     "change of `drum_work` over the window / its length (over the rows so far while the run "
     "is younger than the window)"},
    {"toe_angle", "deg", &SeriesRow::toe_angle, SeriesOnly::kDrum,
     "drum scenes: where the charge meets the shell, from the downward vertical, positive in "
     "the drum's sense of rotation: where the shell layer's occupancy, time-averaged over the "
     "last `output.analysis_window` seconds of rows (this row included), rises through half "
     "its largest value (docs/models.md, \"Mill analytics\"); `nan` when the particles line "
     "the whole shell"},
    {"shoulder_angle", "deg", &SeriesRow::shoulder_angle, SeriesOnly::kDrum,
     "drum scenes: where the charge leaves the shell: where that occupancy falls through half "
     "its largest value, same convention (`toe_angle` + `shell_arc`: above 180 when the "
     "charge is carried past the top)"},
    {"surface_angle", "deg", &SeriesRow::surface_angle, SeriesOnly::kDrum,
     "drum scenes: the bed's free surface now from the horizontal, rising towards the "
     "shoulder, across the chord between `toe_angle` and `shoulder_angle`"},
    {"shell_arc", "deg", &SeriesRow::shell_arc, SeriesOnly::kDrum,
     "drum scenes: the arc from `toe_angle` to `shoulder_angle` (360: the charge lines all of "
     "the shell)"},
    {"com_x", "m", &SeriesRow::com_x, SeriesOnly::kDrum,
     "drum scenes: the charge's centre of mass from the drum centre, horizontal"},
    {"com_y", "m", &SeriesRow::com_y, SeriesOnly::kDrum, "drum scenes: the same, vertical"},
    {"airborne_fraction", "", &SeriesRow::airborne_fraction, SeriesOnly::kDrum,
     "drum scenes: particles without any contact (in free flight) / all particles"},
    {"corotating_fraction", "", &SeriesRow::corotating_fraction, SeriesOnly::kDrum,
     "drum scenes: particles above the drum's axis moving with the shell / all particles"},
    {"regime", "", &SeriesRow::regime, SeriesOnly::kDrum,
     "drum scenes: slumping, rolling, cascading, cataracting or centrifuging over the window "
     "(docs/models.md, \"Regimes\"); `-` until the run is one window old"},
};

// The column names of series.csv, in order ("passes" for the iterative integrator, then the ore
// columns for ore scenes, then the mill analytics for drum scenes).
std::vector<std::string> series_columns(bool iterative, bool ore = false, bool drum = false);

// The column table of docs/output.md (between "<!-- columns: series.csv -->" and
// "<!-- end columns -->"): header, separator and one line per column, each ending in '\n'.
std::string series_columns_markdown();

// A resumed run's CSV file (series.csv, product.csv, breakages.csv, lifters.csv): keeps the
// header and the rows whose value in column `column` is at most `limit`, up to the first row
// that is not (or whose field count is not the header's: a torn last row) (the rows the
// interrupted run wrote after its checkpoint go; the file is rewritten through a temporary
// renamed into place) and
// returns it opened for appending; a missing file is created with the header. Throws IoError
// when it cannot, or when the file's header is not `header` (another kind of run's file).
std::FILE* continue_csv(const std::string& path, const std::string& header, std::size_t column,
                        double limit);

class SeriesWriter {
 public:
  // Creates (truncating) `path` and writes the header row; or, with `continue_after_step` >= 0
  // (a restart), keeps the rows up to that step and appends after them (continue_csv). Throws
  // IoError "cannot create PATH: REASON" when it cannot (active writer only).
  SeriesWriter(const std::string& path, bool iterative, bool active, bool ore = false,
               std::int64_t continue_after_step = -1, bool drum = false);
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
  bool ore_;
  bool drum_;
  std::unique_ptr<std::FILE, Closer> file_;
};

}  // namespace dem2d
