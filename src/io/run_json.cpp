#include "io/run_json.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string_view>

#include "core/base/errors.hpp"
#include "io/deck.hpp"
#include "io/text.hpp"

namespace dem2d {

JsonObject& JsonObject::add(std::string_view key, std::string json) {
  members_.emplace_back(quoted_string(key), std::move(json));
  return *this;
}

JsonObject& JsonObject::add_string(std::string_view key, std::string_view text) {
  return add(key, quoted_string(text));
}

JsonObject& JsonObject::add_integer(std::string_view key, std::int64_t x) {
  return add(key, fmt::format("{}", x));
}

JsonObject& JsonObject::add_number(std::string_view key, double x) {
  return add(key, json_number(x));
}

JsonObject& JsonObject::add_number(std::string_view key, double x, const char* format) {
  return add(key, json_number(x, format));
}

JsonObject& JsonObject::add_members(const JsonObject& other) {
  members_.insert(members_.end(), other.members_.begin(), other.members_.end());
  return *this;
}

std::string JsonObject::inline_text() const {
  std::string out = "{";
  for (const auto& [key, json] : members_)
    out += fmt::format("{}{}: {}", out.size() > 1 ? ", " : "", key, json);
  return out + "}";
}

std::string JsonObject::block_text() const {
  std::string out = "{";
  for (const auto& [key, json] : members_) {
    out += fmt::format("{}\n  {}: ", out.size() > 1 ? "," : "", key);
    for (const char c : json) {
      out += c;
      if (c == '\n') out += "  ";
    }
  }
  return out + "\n}";
}

std::string json_number(double x, const char* format) {
  return std::isfinite(x) ? fmt_double(format, x) : "null";
}

std::string json_array(std::span<const double> values, const char* format) {
  std::string out = "[";
  for (const double v : values) out += (out.size() > 1 ? ", " : "") + json_number(v, format);
  return out + "]";
}

std::string run_json_text(const Scene& scene, const RunInfo& info) {
  JsonObject top;
  top.add_string("version", info.version)
      .add_integer("ranks", info.ranks)
      .add_number("wall_time_s", info.wall_time_s)
      .add_integer("steps", info.steps)
      .add_number("particle_steps_per_second", info.particle_steps_per_second)
      .add_number("dt", info.dt)
      .add_string("deck_path", scene.deck_path)
      .add_members(info.extra)
      .add("deck", resolved_deck_json(scene));
  return top.block_text() + "\n";
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
