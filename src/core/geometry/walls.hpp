// Walls: rigid bodies with a prescribed motion, made of elements a sphere can touch.
//
// Bodies: the drum (rotating about its centre at Omega(t), linear ramp from 0 over ramp_time)
// and each [[wall]] segment (static or translating). Elements: the drum's exact inner circle,
// or the N sides of its regular polygon (vertices on the circle of the drum's radius, thesis
// T 1.6), the three exposed sides of each rectangular lifter (the DEM-FEM study, docs/models.md
// "Sources"), and straight segments. Elements of the drum are stored in the drum frame and placed
// in the lab frame by `update`.
//
// The narrow phase of a particle against an element is its shape's (core/shape/disc.hpp). In
// contact, R* = r_i and m* = m_i, the wall's velocity at the contact point p is u_body + Omega_body
// z x (p - c_body), and w_rel = w_i - Omega_body (docs/models.md).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/base/scene.hpp"
#include "core/base/vec2.hpp"

namespace dem2d {

struct WallBody {
  Vec2 center{};       // rotation centre (drum) or reference point (translating wall)
  double speed = 0.0;  // rad/s at full speed (drum)
  double ramp_time = 0.0;
  double angle0 = 0.0;  // rad, angle at t = 0
  Vec2 velocity{};      // m/s, translation (walls)
  // State at the current time (set by Walls::update).
  double omega = 0.0;
  double angle = 0.0;
  Vec2 offset{};  // translation since t = 0
};

enum class WallKind { kCircle, kSegment };
// What an element belongs to: the drum's shell, a lifter bar (on the drum body), a [[wall]].
enum class WallPart : std::int8_t { kShell, kLifter, kWall };

struct WallElement {
  WallKind kind = WallKind::kSegment;
  WallPart part = WallPart::kShell;
  int body = 0;
  int material = 0;
  double radius = 0.0;    // circle
  Vec2 a_ref{}, b_ref{};  // segment ends in the body frame (relative to the body's centre)
  Vec2 a{}, b{};          // segment ends in the lab frame at the current time
};

// Where the walls stood at a moment (a neighbour-list build): the time and the drum's angle.
struct WallPose {
  double time = 0.0;
  double drum_angle = 0.0;
};

// The walls and their motion. The seam a wall motion plugs into is: update (where the elements
// are at a time), elements (their ends), velocity_at (a point's velocity) and moved_since (how far
// any element point may have moved since a pose); today's motions are prescribed rigid ones,
// the drum's ramped rotation and the [[wall]] segments' translation (docs/extending.md, "A wall
// motion").
class Walls {
 public:
  Walls() = default;
  Walls(const Scene& scene);  // materials resolved by name through `scene`

  void update(double time);  // body states and element lab positions at `time`
  // The centre of a circle element (its body's centre at the current time).
  Vec2 circle_center(const WallElement& e) const {
    return bodies_[e.body].center + bodies_[e.body].offset;
  }
  Vec2 velocity_at(int body, Vec2 p) const {
    const WallBody& b = bodies_[body];
    return b.velocity + b.omega * perp(p - (b.center + b.offset));
  }
  // The pose at `time` (the current one: update's).
  WallPose pose(double time) const { return {time, drum_angle()}; }
  // A bound on how far any element point moves from pose `then` to `ahead` seconds past `time`:
  // the largest distance a rotating element point moves per unit drum angle (0 when nothing but
  // circles rotates) times the angle turned, at most the full speed over `ahead`, plus the
  // fastest translation over the time elapsed.
  double moved_since(const WallPose& then, double time, double ahead) const {
    return rotating_reach_ *
               (std::abs(drum_angle() - then.drum_angle) + std::abs(drum_speed()) * ahead) +
           max_translation_speed() * (time + ahead - then.time);
  }

  const std::vector<WallBody>& bodies() const { return bodies_; }
  const std::vector<WallElement>& elements() const { return elements_; }
  bool has_drum() const { return drum_body_ >= 0; }
  int drum_body() const { return drum_body_; }
  double drum_angle() const { return has_drum() ? bodies_[drum_body_].angle : 0.0; }
  double drum_omega() const { return has_drum() ? bodies_[drum_body_].omega : 0.0; }
  // The drum's full speed (the ramp never exceeds it), rad/s.
  double drum_speed() const { return has_drum() ? bodies_[drum_body_].speed : 0.0; }

 private:
  double max_translation_speed() const;
  std::vector<WallBody> bodies_;
  std::vector<WallElement> elements_;
  int drum_body_ = -1;
  double rotating_reach_ = 0.0;
  std::vector<Vec2> rotation_;  // (cos, sin) of each body's angle (scratch of update)
};

// The walls' outlines at their current time (the last update), in the lab frame, for pictures
// (snapshots.xmf): one polyline per part. The drum's circle as `circle_points` points (at least
// 3) starting at the drum's angle, closed (its first point repeated at the end); a polygonal
// drum as its N sides chained, closed the same way (N + 1 points); each lifter as its three
// exposed sides (4 points, both feet on the shell); each [[wall]] segment as its 2 ends. In
// element order: the drum, its lifters, then the walls. Consecutive segments of one body whose
// ends meet (in the body frame, exactly) are chained into one polyline.
std::vector<std::vector<Vec2>> wall_outlines(const Walls& walls, int circle_points = 256);

// Drum speed and angle at time t for a linear ramp from 0 to `speed` over `ramp` seconds.
double ramp_speed(double speed, double ramp, double t);
double ramp_angle(double speed, double ramp, double t);

}  // namespace dem2d
