// collisions.csv: the collision energy spectra of a run with output.collision_spectra = true
// (core/mill/mill_analytics.hpp, CollisionSpectra; docs/output.md). One row per non-empty bin:
//   type        ball-ball, ball-ore, ore-ore, ball-shell, ball-lifter, ball-wall, ore-shell,
//               ore-lifter, ore-wall
//   size_min, size_max   m, the size class: the smaller particle's diameter (size_max inf for
//                        the last class)
//   energy_min, energy_max   J, the bin of the contact's peak normal strain energy (10 per
//                            decade; the first bin from 0)
//   count       contacts that ended with their peak in the bin, since the start of the run
//   energy      J, the sum of the peaks of the whole (type, size class), on each of its rows
// The file is rewritten whole (a temporary renamed into place) at every snapshot and at the
// end, so it always holds the spectra up to the last of those.
#pragma once

#include <mpi.h>

#include <string>

#include "core/mill/mill_analytics.hpp"

namespace dem2d {

// The text of collisions.csv for spectra already summed over ranks.
std::string collisions_csv(const CollisionSpectra& global);

// Sums the spectra over `comm` and has rank 0 write DIR/collisions.csv (collective). Throws
// IoError on every rank when the file cannot be written.
void write_collisions(MPI_Comm comm, const std::string& directory, const CollisionSpectra& mine);

}  // namespace dem2d
