// checkpoint.h5: everything a run needs to continue exactly (docs/output.md), and reading it
// back for --restart.
//
// Layout (HDF5, written collectively with the MPI-IO driver, read by every rank alone):
//   /                 attributes: format ("dem2d checkpoint 1"), version, ranks, time, step,
//                     dt, skin, halo_width, the balance at the start (baseline_taken,
//                     balance0, motion0, potential0, energy_floor), the pass counters
//                     (passes_last, passes_total, passes_since_row, passes_steps_since_row,
//                     unconverged_steps), neighbor_builds, and for ore scenes the grinding
//                     state (next_id, births_from, next_feed_try, breakages, fragments,
//                     fed_count, discharged_count, fed_mass, discharged_mass)
//   /deck             the resolved deck (one string): what the physics keys are compared with
//   /ranks/NAME       one row per rank of the run's per-rank shares of a sum: dissipated,
//                     drive_work, fed_energy, discharged_energy
//   /guards/kind, /guards/count, /guards/first   guards that fired with run.guards = "warn"
//   /particles/FIELD  every field of the particle store's registry (not only the snapshot
//                     ones: accelerations, forces, inverse masses, damage...), N rows (N x 2
//                     for a vector), rank 0's particles first; each with the attribute
//                     checksum, and /particles with count (N)
//   /contacts/a, /contacts/b, /contacts/history  the committed contact histories keyed by
//                     particle ids (core/contact/contact_history.hpp), M rows (M x width); a pair
//                     that spans two ranks appears once per rank; /contacts has the attributes
//                     width and checksum (of the records: a, b and the history values)
// A checksum (io/checkpoint_checks.hpp, rows_checksum) is the sum over the rows of a hash of each
// row, kept as an int64 of the same bits: the same on any rank count. Reading checks it (a
// checkpoint without one is read without) and the values themselves before any step.
// It is written to checkpoint.h5.tmp and renamed over checkpoint.h5 once closed: a run killed
// during the write keeps the previous checkpoint whole.
#pragma once

#include <string>

#include "core/run/simulation.hpp"
#include "parallel/comm.hpp"

namespace dem2d {

inline constexpr const char* kCheckpointFormat = "dem2d checkpoint 1";

// Collective. Writes the state of `sim` (after a step) to `path`, through `path`.tmp renamed
// into place. Throws IoError with the same message on every rank when it cannot; `path` is
// then left as it was.
void write_checkpoint(MPI_Comm comm, const std::string& path, const Simulation& sim);

// Collective (every rank reads the whole file). The resumption of `scene` from the checkpoint
// at `path`, with the per-rank shares for this rank (the same rank count: its own share; another
// count: rank 0 takes their sum). Throws InputError, alike on every rank, when the file cannot be
// read or is not a dem2d checkpoint, when it is damaged (a checksum that does not match, or
// values no run holds: io/checkpoint_checks.hpp; the message names the dataset, the particle and
// the value), or when the deck's physics keys differ from those the checkpoint was written with
// (the message lists every difference; output keys, run.duration, the title and the
// decomposition keys may change).
Resumption read_checkpoint(MPI_Comm comm, const std::string& path, const Scene& scene);

// Collective, before a --restart from `restart` claims its output folder `dir`: rank 0 checks
// that the output there (if any) is the run's the checkpoint continues, and every rank throws
// the same IoError when it is another run's: its series.csv has other columns than this run
// writes, or its checkpoint.h5 (another file than `restart`) holds a deck of other physics. The
// message names that run (title and deck from its run.json) and what to do.
void check_restart_folder(MPI_Comm comm, const std::string& dir, const std::string& restart,
                          const Scene& scene);

// The keys of `deck` and `checkpoint_deck` (two resolved decks, TOML) whose values differ,
// ignoring the keys a restart may change; each as "KEY: checkpoint VALUE, deck VALUE".
std::vector<std::string> physics_differences(const std::string& checkpoint_deck,
                                             const std::string& deck);

}  // namespace dem2d
