#include "core/walls.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

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
    if (d.sides == 0) {
      WallElement e;
      e.kind = WallKind::kCircle;
      e.body = 0;
      e.material = mat;
      e.radius = d.radius;
      elements_.push_back(e);
    } else {
      // Regular N-gon with its vertices on the circle; vertex k at angle 2 pi k / N.
      const double step = 2.0 * std::numbers::pi / d.sides;
      for (int k = 0; k < d.sides; ++k) {
        WallElement e;
        e.body = 0;
        e.material = mat;
        e.a_ref = {d.radius * std::cos(k * step), d.radius * std::sin(k * step)};
        e.b_ref = {d.radius * std::cos((k + 1) * step), d.radius * std::sin((k + 1) * step)};
        elements_.push_back(e);
        rotating_reach_ = d.radius;
      }
    }
    for (const LifterSpec& l : d.lifters) {
      const int lmat = l.material.empty() ? mat : find_material(scene, l.material);
      // A bar of width w standing on the shell, height h measured radially from the shell's
      // inner surface (the circle, or the polygon's inscribed circle at the bar's foot).
      const double inner =
          d.sides == 0 ? d.radius : d.radius * std::cos(std::numbers::pi / d.sides);
      for (int k = 0; k < l.count; ++k) {
        const double phi = l.angle + 2.0 * std::numbers::pi * k / l.count;
        const Vec2 radial{std::cos(phi), std::sin(phi)};
        const Vec2 side = perp(radial);
        // Feet reach slightly beyond the shell so no gap is left at the base.
        const double foot = std::sqrt(d.radius * d.radius - 0.25 * l.width * l.width);
        const Vec2 p0 = foot * radial - 0.5 * l.width * side;
        const Vec2 p3 = foot * radial + 0.5 * l.width * side;
        const Vec2 p1 = (inner - l.height) * radial - 0.5 * l.width * side;
        const Vec2 p2 = (inner - l.height) * radial + 0.5 * l.width * side;
        for (auto [a, b] : {std::pair{p0, p1}, std::pair{p1, p2}, std::pair{p2, p3}}) {
          WallElement e;
          e.part = WallPart::kLifter;
          e.body = 0;
          e.material = lmat;
          e.a_ref = a;
          e.b_ref = b;
          elements_.push_back(e);
        }
        rotating_reach_ = d.radius;
      }
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
    e.a = origin + rotate(e.a_ref, r);  // core/vec2.hpp: products never fused
    e.b = origin + rotate(e.b_ref, r);
  }
}

WallGeometry Walls::segment_geometry(const WallElement& e, Vec2 x, double r) {
  WallGeometry g;
  // Segment: closest point q on [a, b]; rounded ends.
  const Vec2 ab = e.b - e.a;
  const double len2 = norm2(ab);
  double s = len2 > 0.0 ? dot(x - e.a, ab) / len2 : 0.0;
  s = std::clamp(s, 0.0, 1.0);
  const Vec2 q = e.a + s * ab;
  const Vec2 d = q - x;
  const double dist = norm(d);
  g.n = dist > 0.0 ? (1.0 / dist) * d : perp(ab) * (1.0 / std::sqrt(len2));
  g.delta = r - dist;
  g.point = q;
  return g;
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
