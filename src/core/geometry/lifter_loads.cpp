#include "core/geometry/lifter_loads.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/geometry/drum_geometry.hpp"

namespace dem2d {

LifterBars::LifterBars(const Scene& scene, const Walls& walls) {
  if (!scene.drum.present || !walls.has_drum()) return;
  const DrumGeometry drum(scene.drum);
  for (const DrumGeometry::Bar& b : drum.bars()) phi_.push_back(b.phi);
  if (phi_.empty()) return;
  sense_ = scene.drum.speed < 0.0 ? -1.0 : 1.0;
  const auto& elements = walls.elements();
  const auto first = std::find_if(elements.begin(), elements.end(),
                                  [](const WallElement& e) { return e.part == WallPart::kLifter; });
  first_element_ = static_cast<int>(first - elements.begin());
  const auto lifter_elements =
      std::count_if(elements.begin(), elements.end(),
                    [](const WallElement& e) { return e.part == WallPart::kLifter; });
  if (lifter_elements != static_cast<std::ptrdiff_t>(3 * phi_.size()))
    throw std::logic_error("LifterBars: the walls do not hold three elements per lifter bar");
}

int LifterBars::bar_of(int element) const {
  const int k = element - first_element_;
  if (k < 0 || k >= 3 * static_cast<int>(phi_.size())) return -1;
  return k / 3;
}

Vec2 LifterBars::radial(std::size_t bar, const Walls& walls) const {
  const double theta = walls.drum_angle() + phi_[bar];
  return {std::cos(theta), std::sin(theta)};
}

Vec2 LifterBars::tangential(std::size_t bar, const Walls& walls) const {
  return sense_ * perp(radial(bar, walls));
}

double LifterBars::angle_deg(std::size_t bar, const Walls& walls) const {
  constexpr double kTurn = 2.0 * std::numbers::pi;
  // From the -y direction (lab angle -pi/2), in the sense of rotation.
  double a = std::fmod(sense_ * (walls.drum_angle() + phi_[bar] + 0.5 * std::numbers::pi), kTurn);
  if (a < 0.0) a += kTurn;
  const double deg = a * (180.0 / std::numbers::pi);
  return deg >= 360.0 ? 0.0 : deg;
}

std::vector<LifterContact> LifterBars::contacts(std::span<const WallLoad> loads,
                                                const ParticleStore& p, const Walls& walls) const {
  std::vector<LifterContact> out;
  if (phi_.empty()) return out;
  std::vector<Vec2> radial_of(phi_.size()), tangential_of(phi_.size());
  for (std::size_t b = 0; b < phi_.size(); ++b) {
    radial_of[b] = radial(b, walls);
    tangential_of[b] = tangential(b, walls);
  }
  const Vec2 centre = walls.bodies()[walls.drum_body()].center;
  for (const WallLoad& l : loads) {
    const int bar = bar_of(l.element);
    if (bar < 0) continue;
    LifterContact c;
    c.id = p.id[l.particle];
    c.element = l.element;
    c.bar = bar;
    // The particles' force on the bar is -l.force.
    c.normal = dot(l.force, tangential_of[bar]);
    c.radial = -dot(l.force, radial_of[bar]);
    c.torque = cross(l.point - centre, l.force) + l.couple;  // drive_loads' lifter torque
    out.push_back(c);
  }
  return out;
}

std::vector<LifterLoad> LifterBars::sum(std::vector<LifterContact> all, const Walls& walls) const {
  if (!std::is_sorted(all.begin(), all.end(), key_before))
    std::sort(all.begin(), all.end(), key_before);
  std::vector<LifterLoad> out(phi_.size());
  for (std::size_t b = 0; b < phi_.size(); ++b) out[b].angle_deg = angle_deg(b, walls);
  for (const LifterContact& c : all) {
    LifterLoad& l = out[static_cast<std::size_t>(c.bar)];
    l.normal += c.normal;
    l.radial += c.radial;
    l.torque += c.torque;
    ++l.contacts;
  }
  return out;
}

}  // namespace dem2d
