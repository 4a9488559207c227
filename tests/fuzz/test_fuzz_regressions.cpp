// The deck fuzz target's findings and the hand-made tricky decks (tests/fuzz/regressions/),
// replayed by the ordinary build through exercise_deck, the checks the fuzz target runs on
// every input (docs/fuzzing.md). Each deck is read or refused with an InputError; any other
// exception fails the test, and a crash or a hang fails the whole binary (ctest's timeout).
// The fuzzer's seeds (the shipped decks, tests/fuzz/seeds, tests/cli/broken) go through the same
// replay, and the shipped decks must be read.
#include <gtest/gtest.h>

#include <algorithm>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "core/base/errors.hpp"
#include "fuzz/deck_exercise.hpp"

namespace dem2d::fuzz {
namespace {

namespace fs = std::filesystem;

enum class Outcome { kRead, kRefused, kOther };

// The files of a folder of the source tree, sorted (none when it does not exist).
std::vector<fs::path> files_in(const std::string& folder) {
  const fs::path dir = fs::path(DEM2D_SOURCE_DIR) / folder;
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string bytes_of(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// One input through exercise_deck; anything but a normal return or an InputError is a failure
// naming the file.
Outcome replay(const fs::path& file) {
  try {
    exercise_deck(bytes_of(file));
    return Outcome::kRead;
  } catch (const InputError&) {
    return Outcome::kRefused;
  } catch (const std::exception& e) {
    ADD_FAILURE() << file.string() << ": " << e.what();
  } catch (...) {
    ADD_FAILURE() << file.string() << ": an exception that is no std::exception";
  }
  return Outcome::kOther;
}

TEST(FuzzRegressions, EveryKeptDeckIsReadOrRefused) {
  const std::vector<fs::path> files = files_in("tests/fuzz/regressions");
  ASSERT_FALSE(files.empty()) << "no decks in tests/fuzz/regressions";
  for (const fs::path& file : files) replay(file);
}

TEST(FuzzRegressions, SeedsAreReadOrRefused) {
  for (const std::string folder : {"tests/fuzz/seeds", "tests/cli/broken"}) {
    for (const fs::path& file : files_in(folder)) replay(file);
  }
  const std::vector<fs::path> shipped = files_in("inputs");
  ASSERT_FALSE(shipped.empty());
  for (const fs::path& file : shipped) {
    EXPECT_EQ(replay(file), Outcome::kRead) << file.string() << " is a shipped deck";
  }
}

}  // namespace
}  // namespace dem2d::fuzz
