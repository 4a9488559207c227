// The generated tables of the docs against the descriptions they come from: every key table of
// docs/input.md (the deck's description, io/deck_schema.hpp) and the column table of
// series.csv in docs/output.md (kSeriesColumns, io/series.hpp); the columns of lifters.csv's
// table against the file's header (io/lifter_log.hpp).
//
// A generated table sits between two HTML comments, "<!-- keys: PATH -->" ... "<!-- end keys
// -->" (PATH: "run", "drum.lifter", "top-level") or "<!-- columns: series.csv -->" ...
// "<!-- end columns -->"; the prose around it is written by hand. On a difference the test
// names the key and prints the whole expected table. To rewrite the tables from the
// descriptions (rank 0 writes):
//   DEM2D_UPDATE_DOCS=1 build/tests/test_io --gtest_filter='*Docs.*'
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "io/deck_schema.hpp"
#include "io/lifter_log.hpp"
#include "io/series.hpp"

namespace dem2d {
namespace {

const std::string kInputDocs = std::string(DEM2D_SOURCE_DIR) + "/docs/input.md";
const std::string kOutputDocs = std::string(DEM2D_SOURCE_DIR) + "/docs/output.md";

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

// The generated blocks of a doc, by name: the text between the line "<!-- KIND: NAME -->" and
// the line "<!-- end KIND -->", as offsets into the doc.
struct Block {
  std::size_t begin = 0;
  std::size_t end = 0;
};

std::map<std::string, Block> find_blocks(const std::string& text, const std::string& kind) {
  const std::string open = "<!-- " + kind + ": ";
  const std::string close = "<!-- end " + kind + " -->\n";
  std::map<std::string, Block> blocks;
  for (std::size_t at = text.find(open); at != std::string::npos; at = text.find(open, at)) {
    const std::size_t name_end = text.find(" -->\n", at);
    const std::size_t end = text.find(close, at);
    if (name_end == std::string::npos || end == std::string::npos) {
      ADD_FAILURE() << "unclosed marker at offset " << at;
      break;
    }
    const std::string name = text.substr(at + open.size(), name_end - at - open.size());
    EXPECT_FALSE(blocks.contains(name)) << "two blocks '" << name << "'";
    blocks[name] = {name_end + 5, end};
    at = end;
  }
  return blocks;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The first cell of a Markdown table row ("`dt`" of "| `dt` | float ... |").
std::string first_cell(const std::string& row) {
  const std::size_t start = row.find_first_not_of("| ");
  const std::size_t end = row.find(" |", start);
  return start == std::string::npos ? row : row.substr(start, end - start);
}

// Every difference between the table in the docs and the generated one, naming the key.
std::vector<std::string> table_differences(const std::string& docs, const std::string& expected) {
  std::vector<std::string> problems;
  const std::vector<std::string> have = lines_of(docs);
  const std::vector<std::string> want = lines_of(expected);
  std::map<std::string, std::string> have_rows;
  for (std::size_t i = 2; i < have.size(); ++i) have_rows[first_cell(have[i])] = have[i];
  if (have.size() < 2 || want.size() < 2 || have[0] != want[0] || have[1] != want[1]) {
    problems.push_back("the header differs");
  }
  for (std::size_t i = 2; i < want.size(); ++i) {
    const std::string key = first_cell(want[i]);
    const auto found = have_rows.find(key);
    if (found == have_rows.end()) {
      problems.push_back(key + " is not in the docs");
    } else if (found->second != want[i]) {
      problems.push_back(key + " differs:\n    docs:        " + found->second +
                         "\n    description: " + want[i]);
    }
    if (found != have_rows.end()) have_rows.erase(found);
  }
  for (const auto& [key, row] : have_rows) problems.push_back(key + " is only in the docs");
  if (problems.empty() && docs != expected) problems.push_back("the rows are in another order");
  return problems;
}

bool rank0() {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank == 0;
}

// Checks every generated block of the doc at `path` against `expected` (name -> table text),
// or, with DEM2D_UPDATE_DOCS set, rewrites them (rank 0).
void check_doc(const std::string& path, const std::string& kind,
               const std::map<std::string, std::string>& expected) {
  std::string text = read_text(path);
  ASSERT_FALSE(text.empty()) << "cannot read " << path;
  const std::map<std::string, Block> blocks = find_blocks(text, kind);
  for (const auto& [name, table] : expected) {
    EXPECT_TRUE(blocks.contains(name))
        << path << " has no <!-- " << kind << ": " << name << " --> block; it should hold\n"
        << table;
  }
  for (const auto& [name, block] : blocks) {
    EXPECT_TRUE(expected.contains(name)) << path << ": no table '" << name << "' is described";
  }
  if (std::getenv("DEM2D_UPDATE_DOCS") != nullptr) {
    std::vector<std::pair<Block, std::string>> order;  // back to front, so offsets hold
    for (const auto& [name, block] : blocks) {
      if (expected.contains(name)) order.emplace_back(block, expected.at(name));
    }
    std::sort(order.begin(), order.end(),
              [](const auto& a, const auto& b) { return a.first.begin > b.first.begin; });
    for (const auto& [block, table] : order)
      text.replace(block.begin, block.end - block.begin, table);
    if (rank0()) std::ofstream(path) << text;
    return;
  }
  for (const auto& [name, block] : blocks) {
    if (!expected.contains(name)) continue;
    const std::string docs = text.substr(block.begin, block.end - block.begin);
    for (const std::string& problem : table_differences(docs, expected.at(name))) {
      ADD_FAILURE() << path << ", table '" << name << "': " << problem;
    }
    if (docs != expected.at(name)) {
      ADD_FAILURE() << "the description gives, for '" << name << "':\n" << expected.at(name);
    }
  }
}

TEST(DeckDocs, KeyTablesMatchTheDescription) {
  std::map<std::string, std::string> expected;
  for (const deck::KeyTable& table : deck::key_tables()) {
    expected[table.path.empty() ? "top-level" : table.path] = deck::markdown(table);
  }
  check_doc(kInputDocs, "keys", expected);
}

TEST(SeriesDocs, ColumnsMatchTheTable) {
  check_doc(kOutputDocs, "columns", {{"series.csv", series_columns_markdown()}});
}

// lifters.csv's table in docs/output.md (the first table after its heading) names the file's
// columns, in the header's order.
TEST(LifterDocs, TheTableNamesTheHeadersColumns) {
  const std::string docs = read_text(kOutputDocs);
  const std::size_t section = docs.find("\n## lifters.csv");
  ASSERT_NE(section, std::string::npos) << "docs/output.md has no lifters.csv section";
  std::vector<std::string> documented;
  bool in_table = false;
  for (const std::string& line : lines_of(docs.substr(section + 1))) {
    if (line.starts_with("| ")) {
      in_table = true;
      const std::string cell = first_cell(line);
      if (cell.size() > 2 && cell.front() == '`' && cell.back() == '`')
        documented.push_back(cell.substr(1, cell.size() - 2));
    } else if (in_table) {
      break;
    }
  }
  std::vector<std::string> header;
  std::istringstream in(std::string(kLiftersHeader) + kLiftersShellColumns);
  for (std::string column; std::getline(in, column, ',');) header.push_back(column);
  EXPECT_EQ(documented, header);
}

// The comparison itself: a changed, missing or extra row is named by its key.
TEST(DeckDocs, DifferencesNameTheKey) {
  const std::string header = "| key | type |\n| --- | --- |\n";
  const std::string want = header + "| `a` | float |\n| `b` | bool |\n";
  EXPECT_TRUE(table_differences(want, want).empty());
  const auto changed = table_differences(header + "| `a` | float |\n| `b` | string |\n", want);
  ASSERT_EQ(changed.size(), 1u);
  EXPECT_EQ(changed[0],
            "`b` differs:\n    docs:        | `b` | string |\n    description: | `b` | bool |");
  const auto missing = table_differences(header + "| `a` | float |\n| `c` | bool |\n", want);
  EXPECT_EQ(missing,
            (std::vector<std::string>{"`b` is not in the docs", "`c` is only in the docs"}));
  EXPECT_EQ(table_differences(header + "| `b` | bool |\n| `a` | float |\n", want),
            std::vector<std::string>{"the rows are in another order"});
}

}  // namespace
}  // namespace dem2d
