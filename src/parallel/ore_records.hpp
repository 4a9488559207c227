// The ore scenes' records (breakages, fragments and discharged product, core/mill/grinding.hpp) of
// every rank, brought together for the logs that rank 0 writes (io/ore_logs.hpp).
#pragma once

#include <mpi.h>

#include <vector>

#include "core/mill/grinding.hpp"

namespace dem2d {

struct OreRecords {
  std::vector<BreakageRecord> breakages;
  std::vector<ProductRecord> product;
  std::vector<FragmentRecord> fragments;
};

// Collective over `comm`: every rank's records, concatenated in rank order, on every rank. They
// travel as 64-bit words (doubles bit for bit), one block per rank.
OreRecords gather_ore_records(MPI_Comm comm, const OreRecords& mine);

}  // namespace dem2d
