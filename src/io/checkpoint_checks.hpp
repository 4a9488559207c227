// What a checkpoint must hold before a run continues from it (docs/output.md, "checkpoint.h5 and
// --restart"): the checksums written with it, and the particles and contacts read back checked
// as the deck's own particles are checked before step 1. A damaged checkpoint is bad input, named
// before any step. Internal to the checkpoint reader (checkpoint.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/run/simulation.hpp"

namespace dem2d {

// The checksum of a dataset: the sum (mod 2^64) of a 64-bit hash of each of its `rows` rows of
// `row_bytes` bytes (the values as the machine holds them). A sum does not depend on the order
// of the rows, so every rank adds its own and the run's checksum is their sum, on any number of
// ranks; a changed bit in any row changes it.
std::uint64_t rows_checksum(const std::byte* data, std::size_t rows, std::size_t row_bytes);

// The first thing wrong with the particles and contacts of `r` (its columns in the order of
// `layout`'s fields), as "DATASET: what, which particle, the value" (empty when all is well):
// ids unique and not negative, every value finite, radii, masses and their inverses > 0,
// materials among the scene's, each particle inside the drum and clear of its lifter bars at the
// checkpoint's time up to the placement tolerance (5 % of its radius), the grinding's next id
// above every id, the contacts' values finite.
std::string resumption_problem(const Scene& scene, const ParticleStore& layout,
                               const Resumption& r);

}  // namespace dem2d
