#include "core/geometry/walls.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "core/geometry/drum_geometry.hpp"

namespace dem2d {

double ramp_speed(double speed, double ramp, double t) {
  if (ramp <= 0.0 || t >= ramp) return speed;
  return speed * t / ramp;
}

double ramp_angle(double speed, double ramp, double t) {
  if (ramp <= 0.0) return speed * t;
  if (t < ramp) return 0.5 * speed * t * t / ramp;
  return speed * (t - 0.5 * ramp);
}

Walls::Walls(const Scene& scene) {
  const DrumSpec& d = scene.drum;
  if (d.present) {
    drum_body_ = 0;
    WallBody body;
    body.center = d.center;
    body.speed = d.speed;
    body.ramp_time = d.ramp_time;
    body.angle0 = d.angle;
    bodies_.push_back(body);
    const int mat = find_material(scene, d.material);
    const DrumGeometry drum(d);
    if (d.sides == 0) {
      WallElement e;
      e.kind = WallKind::kCircle;
      e.body = 0;
      e.material = mat;
      e.radius = d.radius;
      elements_.push_back(e);
    } else {
      for (int k = 0; k < d.sides; ++k) {
        WallElement e;
        e.body = 0;
        e.material = mat;
        e.a_ref = drum.vertex(k);
        e.b_ref = drum.vertex(k + 1);
        elements_.push_back(e);
        rotating_reach_ = d.radius;
      }
    }
    for (const DrumGeometry::Bar& bar : drum.bars()) {
      const LifterSpec& l = d.lifters[bar.lifter];
      const int lmat = l.material.empty() ? mat : find_material(scene, l.material);
      for (std::size_t s = 0; s + 1 < bar.corner.size(); ++s) {
        WallElement e;
        e.part = WallPart::kLifter;
        e.body = 0;
        e.material = lmat;
        e.a_ref = bar.corner[s];
        e.b_ref = bar.corner[s + 1];
        elements_.push_back(e);
      }
      rotating_reach_ = d.radius;
    }
  }
  for (const WallSpec& w : scene.walls) {
    WallBody body;
    body.center = w.from;
    body.velocity = w.velocity;
    bodies_.push_back(body);
    WallElement e;
    e.part = WallPart::kWall;
    e.body = static_cast<int>(bodies_.size()) - 1;
    e.material = find_material(scene, w.material);
    e.a_ref = {0.0, 0.0};
    e.b_ref = w.to - w.from;
    elements_.push_back(e);
  }
  update(0.0);
}

double Walls::max_translation_speed() const {
  double v = 0.0;
  for (const WallBody& b : bodies_) v = std::max(v, norm(b.velocity));
  return v;
}

void Walls::update(double time) {
  for (WallBody& b : bodies_) {
    b.omega = ramp_speed(b.speed, b.ramp_time, time);
    b.angle = b.angle0 + ramp_angle(b.speed, b.ramp_time, time);
    b.offset = time * b.velocity;
  }
  // One rotation per body, applied to its elements.
  std::vector<Vec2>& cs = rotation_;
  cs.resize(bodies_.size());
  for (std::size_t k = 0; k < bodies_.size(); ++k)
    cs[k] = {std::cos(bodies_[k].angle), std::sin(bodies_[k].angle)};
  for (WallElement& e : elements_) {
    if (e.kind != WallKind::kSegment) continue;
    const WallBody& b = bodies_[e.body];
    const Vec2 origin = b.center + b.offset;
    const Vec2 r = cs[e.body];
    e.a = origin + rotate(e.a_ref, r);  // core/base/vec2.hpp: products never fused
    e.b = origin + rotate(e.b_ref, r);
  }
}

std::vector<std::vector<Vec2>> wall_outlines(const Walls& walls, int circle_points) {
  std::vector<std::vector<Vec2>> out;
  const WallElement* previous = nullptr;  // the segment that ended the last polyline
  for (const WallElement& e : walls.elements()) {
    const WallBody& body = walls.bodies()[e.body];
    if (e.kind == WallKind::kCircle) {
      const int n = std::max(circle_points, 3);
      const Vec2 c = body.center + body.offset;
      std::vector<Vec2> circle;
      for (int k = 0; k < n; ++k) {
        const double phi = body.angle + 2.0 * std::numbers::pi * k / n;
        circle.push_back(c + e.radius * Vec2{std::cos(phi), std::sin(phi)});
      }
      circle.push_back(circle.front());
      out.push_back(std::move(circle));
      previous = nullptr;
      continue;
    }
    if (previous != nullptr && previous->body == e.body && previous->b_ref == e.a_ref)
      out.back().push_back(e.b);
    else
      out.push_back({e.a, e.b});
    previous = &e;
  }
  // A chain that comes back to its start (the polygon) is closed exactly.
  for (std::vector<Vec2>& line : out) {
    if (line.size() >= 4 && norm(line.back() - line.front()) <= 1e-9 * norm(line[1] - line[0]))
      line.back() = line.front();
  }
  return out;
}

}  // namespace dem2d
