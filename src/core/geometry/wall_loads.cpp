#include "core/geometry/wall_loads.hpp"

namespace dem2d {

// Summed in the records' order, which is the wall list's.
DriveLoads drive_loads(std::span<const WallLoad> loads, const Walls& walls) {
  DriveLoads out;
  const WallElement* elements = walls.elements().data();
  const WallBody* bodies = walls.bodies().data();
  const int drum = walls.drum_body();
  const Vec2 drum_center = walls.has_drum() ? bodies[drum].center : Vec2{};
  for (const WallLoad& l : loads) {
    const WallElement& e = elements[l.element];
    out.power += dot(l.force, l.wall_velocity) + l.couple * bodies[e.body].omega;
    if (e.body != drum) continue;
    const double torque = cross(l.point - drum_center, l.force) + l.couple;
    out.drum_torque += torque;
    if (e.part == WallPart::kLifter) out.lifter_torque += torque;
  }
  return out;
}

}  // namespace dem2d
