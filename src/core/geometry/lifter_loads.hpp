// The load on each lifter bar: the wall load records (core/geometry/wall_loads.hpp) of the bars'
// elements, resolved in each bar's frame and summed per bar (lifters.csv, docs/output.md).
//
// A bar's frame at the walls' current pose: `radial`, the unit vector from the drum's centre
// along the bar (outwards), and `tangential`, perpendicular to it in the drum's sense of rotation
// (counter-clockwise for speed >= 0): the normal of the bar's lifting (leading) face. The
// particles' force on the bar is the negative of the records' `force` (on the particle). Per bar:
//   normal = the particles' force on the bar along -tangential: the load pressing on the lifting
//            face (positive while the bar lifts the charge), the push the bar gives the charge;
//   radial = the particles' force on the bar along radial (positive: pressed towards the shell);
//   torque = the bar's share of the drive's lifter torque: (p - c) x F + couple of each record,
//            as drive_loads sums it.
// The bars are the drum's (DrumGeometry::bars()), in that order; the walls hold three elements
// per bar, consecutive, in the same order.
//
// Sums over bars do not depend on where the records were computed: each record becomes one
// LifterContact keyed by (particle id, element); the contacts of every rank, sorted by that key
// (the order one rank's wall list already has), are added per bar in that order, so the sums
// are the same bits on any rank count.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/base/scene.hpp"
#include "core/geometry/wall_loads.hpp"
#include "core/geometry/walls.hpp"
#include "core/shape/particles.hpp"

namespace dem2d {

// One record on a lifter bar, resolved in the bar's frame.
struct LifterContact {
  std::int64_t id = 0;       // the particle's id
  std::int32_t element = 0;  // into Walls::elements()
  std::int32_t bar = 0;      // into the drum's bars
  double normal = 0.0;       // N, see above
  double radial = 0.0;       // N
  double torque = 0.0;       // N m
};

// The canonical order of the contacts: by particle id, then element (one rank's wall list is
// in this order already).
inline bool key_before(const LifterContact& a, const LifterContact& b) {
  return a.id < b.id || (a.id == b.id && a.element < b.element);
}

// One bar's load at one moment.
struct LifterLoad {
  double angle_deg = 0.0;  // the bar's position, see LifterBars::angle_deg
  double normal = 0.0, radial = 0.0, torque = 0.0;
  std::int64_t contacts = 0;
};

class LifterBars {
 public:
  // The drum's bars (none without a drum or lifters).
  LifterBars(const Scene& scene, const Walls& walls);

  std::size_t size() const { return phi_.size(); }
  bool empty() const { return phi_.empty(); }
  // The bar that element `element` belongs to, or -1 (shell, [[wall]]).
  int bar_of(int element) const;
  // Bar `bar`'s position at the walls' current pose, degrees in [0, 360): the angle of its
  // radial direction from the drum's bottom (the -y direction), measured in the drum's sense of
  // rotation (counter-clockwise for speed >= 0), as the series' toe and shoulder angles are.
  double angle_deg(std::size_t bar, const Walls& walls) const;
  // Its radial direction and the normal of its lifting face, lab frame, at the current pose.
  Vec2 radial(std::size_t bar, const Walls& walls) const;
  Vec2 tangential(std::size_t bar, const Walls& walls) const;

  // This rank's records on the bars, resolved, in the records' order. `p` gives the ids.
  std::vector<LifterContact> contacts(std::span<const WallLoad> loads, const ParticleStore& p,
                                      const Walls& walls) const;
  // Every bar's load from the contacts of all ranks (any order: sorted here by key_before
  // unless they are already, and added per bar in that order), at the walls' current pose.
  std::vector<LifterLoad> sum(std::vector<LifterContact> all, const Walls& walls) const;

 private:
  std::vector<double> phi_;  // each bar's direction in the drum frame, rad
  int first_element_ = 0;    // the first bar's first element
  double sense_ = 1.0;       // +1 counter-clockwise (speed >= 0), -1 clockwise
};

}  // namespace dem2d
