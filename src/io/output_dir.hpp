// The output directory of a run: created and checked once, before anything is written, by
// all ranks together (style.md item 9).
#pragma once

#include <string>

#include "parallel/comm.hpp"

namespace dem2d {

// Collective. Rank 0 creates `dir` (with its parents) and checks that a file can be created
// and removed in it; the outcome is broadcast. On failure every rank throws IoError
// "cannot write to output directory 'DIR': REASON" with the same text.
void prepare_output_directory(MPI_Comm comm, const std::string& dir);

}  // namespace dem2d
