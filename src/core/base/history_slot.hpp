// One declared history value of a contact: the contact models' sub-models and the particle
// shapes declare the slots they keep (core/contact/contact_history.hpp).
#pragma once

#include <string_view>

namespace dem2d {

struct HistorySlot {
  std::string_view name;  // e.g. "xi"
  std::string_view unit;  // SI, e.g. "m"
  std::string_view doc;   // one line
};

}  // namespace dem2d
