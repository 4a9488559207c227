// Small text utilities the io layer shares: TOML/JSON literals, "did you mean" suggestions,
// lists for messages, printf-formatted numbers.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace dem2d {

// A double-quoted string with the escapes TOML basic strings and JSON share
// (\" \\ \n \t \r, \uXXXX for other control characters); UTF-8 passes through.
std::string quoted_string(std::string_view s);

// The shortest text that reads back to the same double. TOML keeps a '.' or an exponent so
// that it stays a float ("2.0", "1e-05") and writes inf / nan as words.
std::string toml_number(double v);
// JSON: the same shortest text ("2", "1e-05"); null for inf and nan, which JSON lacks.
std::string json_number(double v);

// One double through a printf format ("%.4g s"), as snprintf writes it (at most 127
// characters): the run's messages and reports.
std::string fmt_double(const char* format, double x);

std::string lowercase(std::string_view s);
std::string_view trim(std::string_view s);  // spaces, tabs, CR, LF at both ends

// Optimal string alignment distance: insertions, deletions, substitutions and transpositions
// of adjacent characters each cost 1 ("restituion" -> "restitution" is 1).
std::size_t edit_distance(std::string_view a, std::string_view b);

// The candidate that `word` most likely meant, if one is close enough: at most one edit for
// words up to 5 characters, a third of the length for longer ones (case is ignored).
std::optional<std::string_view> closest_match(std::string_view word,
                                              std::span<const std::string_view> candidates);
std::optional<std::string_view> closest_match(std::string_view word,
                                              const std::vector<std::string>& candidates);

// "\"a\", \"b\"" / "a, b" / "a and b", "a, b and c".
std::string quoted_list(std::span<const std::string_view> items);
std::string quoted_list(const std::vector<std::string>& items);
std::string comma_list(std::span<const std::string_view> items);
std::string and_list(std::span<const std::string_view> items);

}  // namespace dem2d
