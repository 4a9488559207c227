// Checks of a scene before step 1 that need what the core derives (docs/input.md, "Checks
// before the run"): the memory the particles will take (before any is placed), where the
// lifters stand, and, once the time step is chosen, how far anything moves in the first step
// and how many steps the run takes. Bad input throws InputError holding every message, each at
// the deck location the reader recorded for the key (Scene::where: "deck.in:7:12: error:
// run.duration = ..."), or at the CSV row ("packing.csv:5: error: fill[1].file row: ...").
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/base/scene.hpp"
#include "core/base/vec2.hpp"
#include "core/shape/particles.hpp"

namespace dem2d {

// The most steps a run may take, run.duration / dt. The clock t = step dt stays exact far
// beyond (step < 2^53, 9e15), but at the fastest dem2d steps (a few million steps/s, one
// particle on one core) 1e12 steps is days of wall time, and a scene of thousands of particles
// takes years: a count above it is a slip of units or of an exponent, not a run.
inline constexpr double kMaxRunSteps = 1.0e12;

// ---------------------------------------------------------------------------------------------
// Memory

// Neighbour pairs listed per particle in the estimate: a disc touches at most 6 equal ones in a
// plane, each pair listed once, and the skin and unequal radii add some.
inline constexpr double kPairsPerParticle = 4.0;

// The particles a fill places: its count, or, for a fill_fraction or bed_filling, the target
// area over the mean area pi E[r^2] of its radius law (uniform in [a, b]: E[r^2] = (a^2 + ab +
// b^2) / 3; size_law.hpp's mean_particle_area), without drawing the radii as fill_count does.
double expected_fill_count(const Scene& scene, std::size_t fill);

// The sites of the lattice a fill lays over its region to place its particles (spacing 2.1
// radius_max over the region's bounding box), which it holds in memory while it places them.
double fill_lattice_sites(const Scene& scene, std::size_t fill);

// Bytes a run holds at its start for `particles` particles: the particle store and the copy
// the run keeps to recover from, the neighbour pairs with their contact histories, all twice
// over for the growth of the arrays and the rebuilds' scratch (as `dem2d --check` prints).
double particle_memory_bytes(const Scene& scene, double particles);

// Bytes a fill's lattice takes while the fill is placed (each site 24 bytes, with the vector's
// growth and the sort's buffer).
double lattice_memory_bytes(double sites);

// The machine's physical memory in bytes (sysconf), 0 when it cannot be told.
double physical_memory_bytes();

// Throws InputError, before anything is placed, when the particles at the start (the deck's
// [[particle]] tables and file rows, and every fill's count or expected count) or the largest
// fill's lattice would need more than `available` bytes; the message names the fill's count
// (fill_fraction, radius) key, the estimate and the memory available.
void check_memory(const Scene& scene, double available);

// ---------------------------------------------------------------------------------------------
// The first step

// Throws InputError when, at time step `dt`, a particle's initial velocity (or spin, turning
// its surface) would carry it more than kMaxStepMotion of its radius in the first step, when
// the fed particles, a [[wall]] or the drum's shell would move that far against the smallest
// particle, or when run.duration / dt rounds to no step or exceeds kMaxRunSteps. `particles`: every
// particle as placed (ids are their indices: [[particle]] tables, file rows, then the fills).
void validate_start(const Scene& scene, const ParticleStore& particles, double dt);

// The output intervals the deck gives (series, snapshots, checkpoints) that are shorter than
// `dt`: an output comes at most once a step, so each is written every step. One note per key,
// "WHERE: note: output.series_interval = 1e-05 s is shorter than one step, dt = ...: written
// every step ...", for the command line to print.
std::vector<std::string> output_interval_notes(const Scene& scene, double dt);

}  // namespace dem2d
