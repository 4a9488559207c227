#include "io/collisions.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>

#include "core/base/errors.hpp"
#include "io/output_dir.hpp"
#include "parallel/comm.hpp"

namespace dem2d {

std::string collisions_csv(const CollisionSpectra& s) {
  std::string out = "type,size_min,size_max,energy_min,energy_max,count,energy\n";
  const std::vector<double>& edges = s.size_edges();
  for (int t = 0; t < static_cast<int>(ContactType::kCount); ++t) {
    const auto type = static_cast<ContactType>(t);
    for (int c = 0; c < s.size_classes(); ++c) {
      const double lo = c == 0 ? 0.0 : edges[static_cast<std::size_t>(c - 1)];
      const double hi = c < static_cast<int>(edges.size())
                            ? edges[static_cast<std::size_t>(c)]
                            : std::numeric_limits<double>::infinity();
      for (int b = 0; b < CollisionSpectra::kEnergyBins; ++b) {
        const std::int64_t n = s.counts()[s.index(type, c, b)];
        if (n == 0) continue;
        const double e_hi = b + 1 < CollisionSpectra::kEnergyBins
                                ? CollisionSpectra::energy_edge(b + 1)
                                : std::numeric_limits<double>::infinity();
        out += fmt::format("{},{:.6g},{:.6g},{:.6g},{:.6g},{},{:.17g}\n", contact_type_name(type),
                           lo, hi, CollisionSpectra::energy_edge(b), e_hi, n,
                           s.energies()[s.cell(type, c)]);
      }
    }
  }
  return out;
}

void write_collisions(MPI_Comm comm, const std::string& directory, const CollisionSpectra& mine) {
  CollisionSpectra global = mine;
  mpi::sum_in_place(comm, std::span<std::int64_t>(global.counts()));
  mpi::sum_in_place(comm, std::span<double>(global.energies()));
  std::string error;
  if (mpi::rank(comm) == 0)
    error = write_file_atomically(directory + "/" + kCollisionsFile, collisions_csv(global));
  mpi::agree_on_failure<IoError>(comm, error);
}

}  // namespace dem2d
