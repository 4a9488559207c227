// run.json: the record of one run, written at its end into the output directory: the
// program version, rank count, timing, and the resolved deck (every default filled in).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/scene.hpp"

namespace dem2d {

struct RunInfo {
  std::string version;
  int ranks = 1;
  double wall_time_s = 0.0;                // s of wall time for the whole run
  std::int64_t steps = 0;                  // time steps taken
  double particle_steps_per_second = 0.0;  // sum over steps of the particle count / wall time
  double dt = 0.0;                         // s, the time step used (resolved when "auto")
  // More top-level members: key, value already encoded as JSON ("3", "\"text\"", "[1, 2]").
  std::vector<std::pair<std::string, std::string>> extra;
};

// {"version": ..., "ranks": ..., "wall_time_s": ..., "steps": ...,
//  "particle_steps_per_second": ..., "dt": ..., "deck_path": ..., <extra>..., "deck": {...}}
std::string run_json_text(const Scene& scene, const RunInfo& info);

// Writes run_json_text to `path` (through a temporary file renamed into place, so a reader
// never sees half a file). Throws IoError when it cannot be written.
void write_run_json(const std::string& path, const Scene& scene, const RunInfo& info);

}  // namespace dem2d
