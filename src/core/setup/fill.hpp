// Initial placement of particles: explicit [[particle]] entries first (deck order), then each
// [[fill]] in deck order. Ids are 0, 1, 2, ... in that order.
//
// A fill places spheres on a hexagonal lattice of spacing 2.1 r_max laid over its region, each
// jittered at random by up to the slack of its site, so no two overlap and none overlaps a wall
// or an earlier particle. Regions: "bottom" takes the lowest sites in the drum (row by row, the
// last row chosen at random), "full" a random subset of all sites in the drum, "annulus" the
// sites nearest the shell first, "box" a random subset of the sites in [box_min, box_max].
// A fill with mix = true is placed together with the fill before it: each keeps its lattice,
// their particles dealt in a shuffled order, each to its lattice's next site clear of those
// placed. Radii follow the fill's size_distribution (size_law.hpp); every draw is keyed by
// (seed, fill, particle), so every rank places the same particles. A fill of superellipses
// places each within its bounding circle (the lattice's r_max is the largest bounding radius),
// turned by a random angle, so none overlaps either.
#pragma once

#include "core/base/scene.hpp"
#include "core/geometry/walls.hpp"
#include "core/setup/validate.hpp"  // check_memory before placing; validate_start once dt is chosen
#include "core/shape/particles.hpp"

namespace dem2d {

// Throws InputError (at the fill's count key, Scene::where) when the particles would not fit in
// the machine's memory (check_memory, before any is placed) or a region cannot hold them.
void place_particles(const Scene& scene, const Walls& walls, ParticleStore& store);

// Number of particles a fill will place (after resolving fill_fraction or bed_filling).
std::int64_t fill_count(const Scene& scene, std::size_t fill_index);

}  // namespace dem2d
