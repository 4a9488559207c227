#include "io/run_json.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string_view>

#include "core/errors.hpp"
#include "io/deck.hpp"
#include "io/text.hpp"

namespace dem2d {

std::string run_json_text(const Scene& scene, const RunInfo& info) {
  std::string out = "{\n";
  const auto member = [&](std::string_view key, std::string_view json) {
    out += fmt::format("  {}: {},\n", quoted_string(key), json);
  };
  member("version", quoted_string(info.version));
  member("ranks", fmt::format("{}", info.ranks));
  member("wall_time_s", json_number(info.wall_time_s));
  member("steps", fmt::format("{}", info.steps));
  member("particle_steps_per_second", json_number(info.particle_steps_per_second));
  member("dt", json_number(info.dt));
  member("deck_path", quoted_string(scene.deck_path));
  for (const auto& [key, json] : info.extra) member(key, json);
  // The deck object, indented one level inside the outer one.
  std::string deck = resolved_deck_json(scene);
  std::string indented;
  for (const char c : deck) {
    indented += c;
    if (c == '\n') indented += "  ";
  }
  out += fmt::format("  {}: {}\n}}\n", quoted_string("deck"), indented);
  return out;
}

void write_run_json(const std::string& path, const Scene& scene, const RunInfo& info) {
  const std::string text = run_json_text(scene, info);
  const std::string temporary = path + ".tmp";
  const auto fail = [&](int error) {
    std::remove(temporary.c_str());
    throw IoError(fmt::format("{}: error: cannot write run.json: {}", path, std::strerror(error)));
  };
  std::FILE* stream = std::fopen(temporary.c_str(), "wb");
  if (stream == nullptr) fail(errno);
  const bool written = std::fwrite(text.data(), 1, text.size(), stream) == text.size();
  const int write_errno = errno;
  if (std::fclose(stream) != 0 || !written) fail(written ? errno : write_errno);
  if (std::rename(temporary.c_str(), path.c_str()) != 0) fail(errno);
}

}  // namespace dem2d
