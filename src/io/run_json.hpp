// run.json: the record of one run, written at its end into the output directory: the
// program version, rank count, timing, and the resolved deck (every default filled in).
// JsonObject writes its members; io/run_info.hpp fills a RunInfo from a finished run.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/base/scene.hpp"

namespace dem2d {

// A JSON object built member by member, in order: the one way run.json's objects are written,
// the top level over several lines and the objects inside it ("mill", "guards_fired") on one.
class JsonObject {
 public:
  // A member whose value is JSON text already: a number, an array, an object, true, null.
  JsonObject& add(std::string_view key, std::string json);
  JsonObject& add_string(std::string_view key, std::string_view text);  // quoted and escaped
  JsonObject& add_integer(std::string_view key, std::int64_t x);
  // The shortest text that reads back to `x` (json_number in io/text.hpp), or `x` through the
  // printf `format` ("%.10g"); null when it is not finite.
  JsonObject& add_number(std::string_view key, double x);
  JsonObject& add_number(std::string_view key, double x, const char* format);
  // The members of `other`, after this one's.
  JsonObject& add_members(const JsonObject& other);
  bool empty() const { return members_.empty(); }

  // {"a": 1, "b": [2, 3]}; {} when empty.
  std::string inline_text() const;
  // One member a line, indented by two spaces (a value over several lines by two more):
  // {\n  "a": 1,\n  "b": {\n    "c": 2\n  }\n}
  std::string block_text() const;

 private:
  std::vector<std::pair<std::string, std::string>> members_;  // quoted key, JSON value
};

// `x` through the printf `format`; null when it is not finite.
std::string json_number(double x, const char* format);
// [a, b, c]: each value through json_number(value, format).
std::string json_array(std::span<const double> values, const char* format);

struct RunInfo {
  std::string version;
  int ranks = 1;
  double wall_time_s = 0.0;                // s of wall time for the whole run
  std::int64_t steps = 0;                  // time steps taken
  double particle_steps_per_second = 0.0;  // sum over steps of the particle count / wall time
  double dt = 0.0;                         // s, the time step used (resolved when "auto")
  JsonObject extra;                        // more top-level members, after "deck_path"
};

// {"version": ..., "ranks": ..., "wall_time_s": ..., "steps": ...,
//  "particle_steps_per_second": ..., "dt": ..., "deck_path": ..., <extra>..., "deck": {...}}
std::string run_json_text(const Scene& scene, const RunInfo& info);

// Writes run_json_text to `path` (through a temporary file renamed into place, so a reader
// never sees half a file). Throws IoError when it cannot be written.
void write_run_json(const std::string& path, const Scene& scene, const RunInfo& info);

}  // namespace dem2d
