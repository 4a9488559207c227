// lifters.csv of drum scenes with lifter bars (docs/output.md): at every series row, one row per
// bar, in the drum's bar order: time, lifter, angle_deg, normal_N, radial_N, torque_Nm, contacts
// (core/geometry/lifter_loads.hpp for the definitions), and with a [shell] the bar's
// tip_deflection_m, von_mises_max_Pa and root_stress_Pa (core/structure/shell.hpp). Doubles
// with %.17g; each row group is flushed. Only the active writer (rank 0) touches the file.
#pragma once

#include <cstdio>
#include <memory>
#include <span>
#include <string>

#include "core/geometry/lifter_loads.hpp"
#include "core/structure/shell.hpp"

namespace dem2d {

inline constexpr const char* kLiftersHeader =
    "time,lifter,angle_deg,normal_N,radial_N,torque_Nm,contacts";
inline constexpr const char* kLiftersShellColumns =
    ",tip_deflection_m,von_mises_max_Pa,root_stress_Pa";

class LifterLog {
 public:
  // Creates (truncating) `path` with the header; or, with `continue_after_time` >= 0 (a
  // restart), keeps its rows up to that time and appends after them. Throws IoError when it
  // cannot.
  // `shell`: the rows carry the shell's columns.
  LifterLog(const std::string& path, bool active, bool shell, double continue_after_time = -1.0);
  // Appends one row per bar at `time`, with the shell's columns when `shell` is not empty (one
  // per bar). Throws IoError "cannot write PATH: REASON".
  void write(double time, std::span<const LifterLoad> bars, std::span<const ShellBar> shell = {});

 private:
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::string path_;
  std::unique_ptr<std::FILE, Closer> file_;
};

}  // namespace dem2d
