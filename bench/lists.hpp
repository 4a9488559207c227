// The benches' comma-separated option values ("1000,3000,1e4"): each item read as a double and
// converted to T, empty items skipped.
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace bench {

template <class T>
std::vector<T> parse_list(const std::string& s) {
  std::vector<T> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(static_cast<T>(std::stod(item)));
  return out;
}

}  // namespace bench
