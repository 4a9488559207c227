// SeriesWriter: series.csv, one row of global diagnostics per series interval
// (docs/output.md lists the columns, their units and the energy balance).
//
// Doubles are written with %.17g, so strtod reads back the exact bits; integers as integers.
// Each row is flushed, so a crash loses nothing already written. Only the active writer
// (rank 0) touches the file; the others do nothing.
#pragma once

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/diagnostics.hpp"

namespace dem2d {

// The column names of series.csv, in order ("passes" last, for the iterative integrator).
std::vector<std::string> series_columns(bool iterative);

class SeriesWriter {
 public:
  // Creates (truncating) `path` and writes the header row. Throws IoError
  // "cannot create PATH: REASON" when it cannot (active writer only).
  SeriesWriter(const std::string& path, bool iterative, bool active);
  ~SeriesWriter();  // flushes and closes; never throws
  SeriesWriter(const SeriesWriter&) = delete;
  SeriesWriter& operator=(const SeriesWriter&) = delete;

  // Appends one row and flushes it. Throws IoError "cannot write PATH: REASON".
  void write(const SeriesRow& row);

  const std::string& path() const { return path_; }

 private:
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  void put(const std::string& text);

  std::string path_;
  bool iterative_;
  std::unique_ptr<std::FILE, Closer> file_;
};

}  // namespace dem2d
