// series.csv's columns come from kSeriesColumns (io/series.hpp): the header and the bytes of a
// row are those of the hand-written format string the table replaced, and "passes" is written
// only with the iterative integrator. Each rank writes a file of its own.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "io/series.hpp"

namespace dem2d {
namespace {

namespace fs = std::filesystem;

// The header and first row of a series.csv written with `row`.
std::pair<std::string, std::string> written(const SeriesRow& row, bool iterative) {
  const fs::path path =
      fs::temp_directory_path() / ("dem2d_series_columns_" + std::to_string(::getpid()) + ".csv");
  {
    SeriesWriter writer(path.string(), iterative, true);
    writer.write(row);
  }
  std::ifstream in(path);
  std::string header, line;
  std::getline(in, header);
  std::getline(in, line);
  fs::remove(path);
  return {header, line};
}

TEST(SeriesColumns, RowsKeepTheirBytes) {
  // Values whose text shows the formats: 17 digits, subnormals, signed zero, large integers.
  const SeriesRow r{.time = 0.1,
                    .step = 9007199254740993,
                    .particles = 240,
                    .contacts = -1,
                    .kinetic_energy = 1.0 / 3.0,
                    .rotational_energy = 2e-300,
                    .potential_energy = -42.067967666792178,
                    .elastic_energy = 5e-324,
                    .dissipated_energy = 1e300,
                    .drum_torque = -0.0,
                    .drum_power = 3.14159,
                    .drive_work = 1.5,
                    .passes = 2.25};
  // The format string that SeriesWriter::write had before the table.
  const std::string row = fmt::format(
      "{:.17g},{},{},{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}", r.time,
      r.step, r.particles, r.contacts, r.kinetic_energy, r.rotational_energy, r.potential_energy,
      r.elastic_energy, r.dissipated_energy, r.drum_torque, r.drum_power, r.drive_work);
  const std::string header =
      "time,step,particles,contacts,kinetic_energy,rotational_energy,potential_energy,"
      "elastic_energy,dissipated_energy,drum_torque,drum_power,drive_work";

  const auto [verlet_header, verlet_row] = written(r, false);
  EXPECT_EQ(verlet_header, header);
  EXPECT_EQ(verlet_row, row);
  const auto [iterative_header, iterative_row] = written(r, true);
  EXPECT_EQ(iterative_header, header + ",passes");
  EXPECT_EQ(iterative_row, row + fmt::format(",{:.17g}", r.passes));
}

TEST(SeriesColumns, DocsTableHasEveryColumn) {
  const std::string table = series_columns_markdown();
  for (const std::string& name : series_columns(true)) {
    EXPECT_NE(table.find("| `" + name + "` |"), std::string::npos) << name;
  }
  EXPECT_NE(table.find("| `step` | – |"), std::string::npos);  // no unit: a dash
}

}  // namespace
}  // namespace dem2d
