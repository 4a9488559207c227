#include "io/deck_diagnostics.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstddef>
#include <sstream>

#include "io/text.hpp"

namespace dem2d::deck {
namespace {

// A node as it would be written in TOML, for messages (shortest round-trip numbers).
std::string value_text(const toml::node& node) {
  if (const auto* s = node.as_string()) return quoted_string(s->get());
  if (const auto* i = node.as_integer()) return fmt::format("{}", i->get());
  if (const auto* f = node.as_floating_point()) return toml_number(f->get());
  if (const auto* b = node.as_boolean()) return b->get() ? "true" : "false";
  if (node.is_table()) return "{...}";
  if (const auto* a = node.as_array()) {
    constexpr std::size_t kShown = 6;
    std::string out = "[";
    for (std::size_t i = 0; i < a->size() && i < kShown; ++i) {
      if (i > 0) out += ", ";
      out += value_text(*a->get(i));
    }
    if (a->size() > kShown) out += ", ...";
    return out + "]";
  }
  std::ostringstream os;  // dates and times
  node.visit([&](const auto& v) { os << v; });
  return os.str();
}

}  // namespace

void Diagnostics::set_source(std::string_view text) {
  for (std::size_t start = 0; start <= text.size();) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    lines_.push_back(text.substr(start, end - start));
    start = end + 1;
  }
}

std::string Diagnostics::shown(const toml::node& node) const {
  const toml::source_position& begin = node.source().begin;
  const toml::source_position& end = node.source().end;
  if (!origins_.contains(&node) && begin.line > 0 && begin.line == end.line &&
      begin.line <= lines_.size() && end.column > begin.column &&
      end.column - 1 <= lines_[begin.line - 1].size()) {
    return std::string(lines_[begin.line - 1].substr(begin.column - 1, end.column - begin.column));
  }
  return value_text(node);
}

void Diagnostics::error_at_key(const toml::key& key, const toml::node& value,
                               std::string_view message) {
  if (!origins_.contains(&value) && key.source().begin.line > 0) {
    add(position(key.source().begin), message);
  } else {
    add(location(value), message);
  }
}

std::string Diagnostics::position(const toml::source_position& at) const {
  return fmt::format("{}:{}:{}", file_, at.line, at.column);
}

std::string Diagnostics::location(const toml::node& node) const {
  if (const auto it = origins_.find(&node); it != origins_.end()) return it->second;
  if (&node == root_ || node.source().begin.line == 0) return file_;
  return position(node.source().begin);
}

void Diagnostics::add(std::string_view where, std::string_view message) {
  messages_.push_back(fmt::format("{}: error: {}", where, message));
}

}  // namespace dem2d::deck
