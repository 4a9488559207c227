// product.csv, breakages.csv and fragments.csv of ore scenes (docs/output.md): one row per
// discharged particle (time, id, radius, mass), one per breakage (time, parent id, radius, the
// parent's share of the breaking loading, fragment count, first fragment id, mass, specific
// energy, t10, fines mass) and one per fragment (time, parent id, id, radius, mass). Rows are
// appended in (time, id) order and flushed at every series row; only the active writer
// (rank 0) touches the files.
#pragma once

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "core/mill/grinding.hpp"

namespace dem2d {

class OreLogs {
 public:
  // Creates (truncating) both files with their headers; or, with `continue_after_time` >= 0 (a
  // restart), keeps their rows up to that time and appends after them. Throws IoError when it
  // cannot.
  OreLogs(const std::string& directory, bool active, double continue_after_time = -1.0);
  // Appends the records (of every rank, gathered by the caller), sorted by (time, id).
  void write(std::vector<BreakageRecord> breakages, std::vector<ProductRecord> product,
             std::vector<FragmentRecord> fragments);

 private:
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  void put(std::FILE* f, const std::string& path, const std::string& text);
  std::string product_path_, breakages_path_, fragments_path_;
  std::unique_ptr<std::FILE, Closer> product_, breakages_, fragments_;
};

}  // namespace dem2d
