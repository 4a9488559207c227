#include "core/structure/shell.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/geometry/drum_geometry.hpp"
#include "core/structure/fe_mesh.hpp"

namespace dem2d {

namespace {

FeModel shell_model(const Scene& scene) {
  const ShellSpec& s = scene.shell;
  ShellMeshSpec spec;
  spec.thickness = s.thickness;
  spec.elements_through_thickness = s.elements_through_thickness;
  spec.element_size = s.element_size.value_or(s.thickness);
  const std::string& name = s.material.empty() ? scene.drum.material : s.material;
  const int m = find_material(scene, name);
  if (m < 0) throw std::invalid_argument("the shell's material " + name + " is not defined");
  const MaterialSpec& mat = scene.materials[static_cast<std::size_t>(m)];
  return FeModel(shell_mesh(DrumGeometry(scene.drum), spec),
                 ElasticMaterial{mat.youngs_modulus, mat.poisson_ratio, mat.density});
}

}  // namespace

Shell::Shell(const Scene& scene, const Walls& walls)
    : model_(shell_model(scene)),
      map_(model_.mesh(), walls.elements()),
      centre_(scene.drum.center),
      depth_(scene.shell.depth),
      sense_(scene.drum.speed >= 0.0 ? 1.0 : -1.0) {
  if (!(depth_ > 0.0)) throw std::invalid_argument("the shell's depth must be positive");
}

FeVector Shell::nodal_loads(std::span<const WallLoad> records, const Walls& walls,
                            std::size_t* placed) const {
  FeVector f = FeVector::Zero(static_cast<Eigen::Index>(model_.dofs()));
  const std::size_t n = map_.add(records, walls.drum_angle(), centre_, depth_, f);
  if (placed != nullptr) *placed = n;
  return f;
}

ShellResponse Shell::respond(std::span<const WallLoad> records, const Walls& walls,
                             bool check) const {
  ShellResponse out;
  const double angle = walls.drum_angle();
  const FeVector f = nodal_loads(records, walls, &out.records);
  for (const WallLoad& l : records) {
    if (walls.elements()[static_cast<std::size_t>(l.element)].part == WallPart::kWall) continue;
    out.applied += rotate(l.force, -angle) * (-1.0 / depth_);
  }
  const FeVector u = model_.solve(f);
  for (Eigen::Index k = 0; k + 1 < f.size(); k += 2) {
    out.nodal += Vec2{f[k], f[k + 1]};
    out.max_displacement = std::max(out.max_displacement, norm(Vec2{u[k], u[k + 1]}));
  }
  if (check) {
    const FeVector r = model_.reactions(u, f);
    for (Eigen::Index k = 0; k + 1 < r.size(); k += 2) out.reaction += Vec2{r[k], r[k + 1]};
  }
  const std::size_t bars = model_.mesh().bars.size();
  out.bars.resize(bars);
  for (std::size_t b = 0; b < bars; ++b) {
    const BarResponse resp = model_.bar_response(b, u);
    // tip_side is counter-clockwise; the lifting face's normal (tangential) is sense_ times it.
    out.bars[b] = {0.0 - sense_ * resp.tip_side, resp.peak_von_mises,
                   model_.bar_root(b, f).nominal_stress};
  }
  return out;
}

ShellField Shell::field(std::span<const WallLoad> records, const Walls& walls) const {
  const double angle = walls.drum_angle();
  const FeVector u = model_.solve(nodal_loads(records, walls, nullptr));
  const FeStress stress = model_.stress(u);
  const std::vector<Vec2>& nodes = model_.mesh().nodes;
  ShellField out;
  out.position.reserve(nodes.size());
  out.displacement.reserve(nodes.size());
  out.von_mises.reserve(nodes.size());
  const Vec2 turn{std::cos(angle), std::sin(angle)};
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const auto at = static_cast<Eigen::Index>(2 * k);
    out.position.push_back(centre_ + rotate(nodes[k], turn));
    out.displacement.push_back(rotate(Vec2{u[at], u[at + 1]}, turn));
    out.von_mises.push_back(stress.nodal[k].von_mises());
  }
  return out;
}

}  // namespace dem2d
