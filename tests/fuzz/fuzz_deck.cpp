// libFuzzer target for the deck reader and validator (docs/fuzzing.md): every input goes
// through exercise_deck (deck_exercise.hpp). Bad input ends in an InputError, which is
// expected; anything else is a finding: another exception escaping (libFuzzer reports the
// abort), a crash or undefined behaviour (ASan, UBSan), a hang (-timeout) or an allocation
// beyond -malloc_limit_mb.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/base/errors.hpp"
#include "deck_exercise.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    dem2d::fuzz::exercise_deck(std::string_view(reinterpret_cast<const char*>(data), size));
  } catch (const dem2d::InputError&) {
    // Bad input, reported as such: what the reader is for.
  }
  return 0;
}
