// Wall loads: what the particles do to the walls, one record per wall contact of a force
// evaluation, in the wall list's order (the same on every run and, merged by element and
// particle id, on any rank count). The force kernel writes them; consumers read them: the drive
// (drum torque, lifter torque and the power of the moving walls, below) is the first; a
// structural model of the shell receives the same records (docs/extending.md, "A consumer of
// wall loads").
#pragma once

#include <cstdint>
#include <span>

#include "core/base/vec2.hpp"
#include "core/geometry/walls.hpp"

namespace dem2d {

struct WallLoad {
  std::int32_t element = 0;   // into Walls::elements()
  std::int32_t particle = 0;  // local index of the particle
  Vec2 point{};               // contact point on the element, lab frame, at the evaluation
  Vec2 force{};               // on the particle; the wall receives -force at `point`
  double couple = 0.0;        // rolling-resistance moment on the particle; the wall gets -couple
  Vec2 wall_velocity{};       // the element's velocity at `point`
};

// The drive's view of the loads: the torque the drive applies to keep the drum turning (N m,
// the reaction of the particles' moments about its centre), the part of it through the lifter
// bars, and the power the moving walls deliver to the particles (F . v_wall + couple Omega).
struct DriveLoads {
  double drum_torque = 0.0, lifter_torque = 0.0, power = 0.0;
};
DriveLoads drive_loads(std::span<const WallLoad> loads, const Walls& walls);

}  // namespace dem2d
