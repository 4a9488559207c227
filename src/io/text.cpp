#include "io/text.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>

namespace dem2d {

std::string quoted_string(std::string_view s) {
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
          out += fmt::format("\\u{:04X}", static_cast<unsigned>(static_cast<unsigned char>(c)));
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

namespace {

// The shortest decimal that reads back to `v` (finite), with an exponent where that is
// shorter: "0.25", "7800", "2e11", "1.5e-05" -> "1.5e-5".
std::string shortest_number(double v) {
  std::string s = fmt::format("{}", v);
  if (const std::size_t e = s.find('e'); e != std::string::npos) {
    // fmt writes "1e-05" / "1e+20": drop the '+' and the exponent's leading zeros.
    std::string exponent = s.substr(e + 1);
    const bool negative = exponent.front() == '-';
    exponent.erase(0, exponent.find_first_not_of("+-"));
    exponent.erase(0, std::min(exponent.find_first_not_of('0'), exponent.size() - 1));
    return s.substr(0, e + 1) + (negative ? "-" : "") + exponent;
  }
  // A whole number with many trailing zeros ("200000000000") as mantissa and exponent.
  const std::size_t sign = s.front() == '-' ? 1 : 0;
  if (s.find('.') != std::string::npos || s.size() - sign < 7) return s;
  const std::size_t last = s.find_last_not_of('0');
  const std::size_t zeros = s.size() - 1 - last;
  if (zeros < 4) return s;
  const std::string digits = s.substr(sign, last + 1 - sign);
  const std::size_t exponent = zeros + digits.size() - 1;
  const std::string_view fraction = std::string_view(digits).substr(1);  // "" or "1" of "21"
  return fmt::format("{}{}{}{}e{}", sign ? "-" : "", digits.front(), fraction.empty() ? "" : ".",
                     fraction, exponent);
}

}  // namespace

std::string toml_number(double v) {
  if (!std::isfinite(v)) return fmt::format("{}", v);  // "inf", "-inf", "nan"
  std::string s = shortest_number(v);
  if (s.find_first_of(".eE") == std::string::npos) s += ".0";  // stays a float
  return s;
}

std::string json_number(double v) { return std::isfinite(v) ? shortest_number(v) : "null"; }

std::string fmt_double(const char* format, double x) {
  char buf[128];
  std::snprintf(buf, sizeof buf, format, x);
  return buf;
}

std::string lowercase(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

std::string_view trim(std::string_view s) {
  const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  const std::size_t n = a.size(), m = b.size();
  std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1, 0));
  for (std::size_t i = 0; i <= n; ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= m; ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= n; ++i) {
    for (std::size_t j = 1; j <= m; ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[n][m];
}

std::optional<std::string_view> closest_match(std::string_view word,
                                              std::span<const std::string_view> candidates) {
  std::optional<std::string_view> best;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  const std::string lower = lowercase(word);
  const std::size_t limit = std::max<std::size_t>(1, word.size() / 3);
  for (const std::string_view candidate : candidates) {
    // The distance is at least the difference in length: a candidate too short or too long is
    // skipped before its table is built (a 30 000-character key would need gigabytes).
    const std::size_t gap = lower.size() > candidate.size() ? lower.size() - candidate.size()
                                                            : candidate.size() - lower.size();
    if (gap > limit) continue;
    const std::size_t distance = edit_distance(lower, lowercase(candidate));
    if (distance < best_distance) {
      best = candidate;
      best_distance = distance;
    }
  }
  if (best && best_distance <= limit) return best;
  return std::nullopt;
}

std::optional<std::string_view> closest_match(std::string_view word,
                                              const std::vector<std::string>& candidates) {
  // The views point into the strings of `candidates`, so the result outlives `views`.
  const std::vector<std::string_view> views(candidates.begin(), candidates.end());
  return closest_match(word, std::span<const std::string_view>(views));
}

std::string quoted_list(std::span<const std::string_view> items) {
  std::string out;
  for (const std::string_view item : items) {
    if (!out.empty()) out += ", ";
    out += quoted_string(item);
  }
  return out;
}

std::string quoted_list(const std::vector<std::string>& items) {
  const std::vector<std::string_view> views(items.begin(), items.end());
  return quoted_list(std::span<const std::string_view>(views));
}

std::string comma_list(std::span<const std::string_view> items) {
  std::string out;
  for (const std::string_view item : items) {
    if (!out.empty()) out += ", ";
    out += item;
  }
  return out;
}

std::string and_list(std::span<const std::string_view> items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (i > 0) out += i + 1 == items.size() ? " and " : ", ";
    out += items[i];
  }
  return out;
}

}  // namespace dem2d
