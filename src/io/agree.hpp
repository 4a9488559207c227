// Agreeing on an I/O failure across ranks, so that no rank throws alone and leaves the others
// waiting in a collective call (style.md item 9).
#pragma once

#include <mpi.h>

#include <string>

namespace dem2d {

// Collective. `error` is this rank's failure message, empty if it succeeded. When any rank
// failed, every rank throws IoError with the message of the lowest failing rank, so all
// ranks report the same text; otherwise it returns on every rank.
void throw_if_any_rank_failed(MPI_Comm comm, const std::string& error);

}  // namespace dem2d
