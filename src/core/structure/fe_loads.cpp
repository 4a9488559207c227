#include "core/structure/fe_loads.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "core/structure/q9_element.hpp"

namespace dem2d {
namespace {

Vec2 edge_tangent(const FeMesh& mesh, const FeEdge& edge, double xi) {
  const std::array<double, 3> d = lagrange3_derivative(xi);
  Vec2 t{};
  for (int a = 0; a < 3; ++a) t += d[a] * mesh.nodes[static_cast<std::size_t>(edge.node[a])];
  return t;
}

// The parameter of the point of `edge` nearest to p: the best of a few samples, refined by
// Newton's method on (x(xi) - p) . x'(xi) = 0, kept in [-1, 1].
double nearest_xi(const FeMesh& mesh, const FeEdge& edge, Vec2 p) {
  double best = -1.0, best_d = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= 8; ++k) {
    const double xi = -1.0 + 0.25 * k;
    const double d = norm2(edge_point(mesh, edge, xi) - p);
    if (d < best_d) best_d = d, best = xi;
  }
  Vec2 second{};  // x''(xi), constant on a quadratic edge
  const std::array<double, 3> dd{1.0, -2.0, 1.0};
  for (int a = 0; a < 3; ++a) second += dd[a] * mesh.nodes[static_cast<std::size_t>(edge.node[a])];
  double xi = best;
  for (int it = 0; it < 20; ++it) {
    const Vec2 r = edge_point(mesh, edge, xi) - p;
    const Vec2 t = edge_tangent(mesh, edge, xi);
    const double g = dot(r, t), h = dot(t, t) + dot(r, second);
    if (!(h > 0.0)) break;
    const double next = std::clamp(xi - g / h, -1.0, 1.0);
    const bool done = std::abs(next - xi) < 1e-15;
    xi = next;
    if (done) break;
  }
  return xi;
}

}  // namespace

Vec2 edge_point(const FeMesh& mesh, const FeEdge& edge, double xi) {
  const std::array<double, 3> n = lagrange3(xi);
  Vec2 x{};
  for (int a = 0; a < 3; ++a) x += n[a] * mesh.nodes[static_cast<std::size_t>(edge.node[a])];
  return x;
}

EdgePoint nearest_edge_point(const FeMesh& mesh, std::span<const std::size_t> edges, Vec2 p) {
  EdgePoint best;
  best.distance = std::numeric_limits<double>::infinity();
  for (const std::size_t e : edges) {
    const double xi = nearest_xi(mesh, mesh.loaded_edges[e], p);
    const double d = norm(edge_point(mesh, mesh.loaded_edges[e], xi) - p);
    if (d < best.distance) best = {e, xi, d};
  }
  if (edges.empty()) throw std::invalid_argument("nearest_edge_point: no edges");
  return best;
}

void add_point_force(const FeEdge& edge, double xi, Vec2 force, FeVector& f) {
  const std::array<double, 3> n = lagrange3(xi);
  for (int a = 0; a < 3; ++a) {
    f(2 * edge.node[a]) += n[a] * force.x;
    f(2 * edge.node[a] + 1) += n[a] * force.y;
  }
}

void add_point_force(const FeMesh& mesh, Vec2 p, Vec2 force, FeVector& f) {
  std::vector<std::size_t> all(mesh.loaded_edges.size());
  for (std::size_t e = 0; e < all.size(); ++e) all[e] = e;
  const EdgePoint at = nearest_edge_point(mesh, all, p);
  add_point_force(mesh.loaded_edges[at.edge], at.xi, force, f);
}

void add_edge_traction(const FeMesh& mesh, const FeEdge& edge,
                       const std::function<Vec2(Vec2, Vec2)>& traction, FeVector& f) {
  for (int g = 0; g < 3; ++g) {
    const double xi = kGauss3[g];
    const Vec2 t = edge_tangent(mesh, edge, xi);
    const double length = norm(t);  // |dx/dxi|
    const Vec2 normal{t.y / length, -t.x / length};
    const Vec2 load = (kGauss3Weight[g] * length) * traction(edge_point(mesh, edge, xi), normal);
    add_point_force(edge, xi, load, f);
  }
}

void add_inner_pressure(const FeMesh& mesh, double pressure, FeVector& f) {
  for (const FeEdge& e : mesh.loaded_edges)
    add_edge_traction(
        mesh, e, [pressure](Vec2, Vec2 n) { return pressure * n; }, f);
}

WallLoadMap::WallLoadMap(const FeMesh& mesh, std::span<const WallElement> elements)
    : mesh_(&mesh), targets_(elements.size()), shell_(elements.size(), 0) {
  for (std::size_t e = 0; e < mesh.loaded_edges.size(); ++e) {
    if (mesh.loaded_edges[e].bar >= 0) continue;
    const Vec2 a = mesh.nodes[static_cast<std::size_t>(mesh.loaded_edges[e].node[0])];
    double angle = std::atan2(a.y, a.x);
    if (angle < 0.0) angle += 2.0 * std::numbers::pi;
    ring_.emplace_back(angle, e);
  }
  std::sort(ring_.begin(), ring_.end());
  std::size_t lifter = 0;
  for (std::size_t w = 0; w < elements.size(); ++w) {
    if (elements[w].part == WallPart::kShell) {
      if (elements[w].kind != WallKind::kCircle)
        throw std::invalid_argument("WallLoadMap: only the circular shell is meshed");
      shell_[w] = 1;
    } else if (elements[w].part == WallPart::kLifter) {
      const int bar = static_cast<int>(lifter / 3), face = static_cast<int>(lifter % 3);
      for (std::size_t e = 0; e < mesh.loaded_edges.size(); ++e)
        if (mesh.loaded_edges[e].bar == bar && mesh.loaded_edges[e].face == face)
          targets_[w].push_back(e);
      ++lifter;
    }
  }
  if (lifter != 3 * mesh.bars.size())
    throw std::invalid_argument("WallLoadMap: the walls do not hold three elements per mesh bar");
}

std::vector<std::size_t> WallLoadMap::ring_candidates(Vec2 p) const {
  if (ring_.size() <= 3) {
    std::vector<std::size_t> all;
    for (const auto& r : ring_) all.push_back(r.second);
    return all;
  }
  double angle = std::atan2(p.y, p.x);
  if (angle < 0.0) angle += 2.0 * std::numbers::pi;
  const auto after =
      std::upper_bound(ring_.begin(), ring_.end(), std::pair{angle, std::size_t{0}},
                       [](const auto& a, const auto& b) { return a.first < b.first; });
  const std::size_t n = ring_.size();
  const std::size_t k =
      after == ring_.begin() ? n - 1 : static_cast<std::size_t>(after - ring_.begin()) - 1;
  return {ring_[(k + n - 1) % n].second, ring_[k].second, ring_[(k + 1) % n].second};
}

std::size_t WallLoadMap::add(std::span<const WallLoad> loads, double drum_angle, Vec2 centre,
                             double depth, FeVector& f) const {
  if (!(depth > 0.0)) throw std::invalid_argument("WallLoadMap: the depth must be positive");
  std::size_t placed = 0;
  for (const WallLoad& l : loads) {
    const auto w = static_cast<std::size_t>(l.element);
    if (!shell_.at(w) && targets_[w].empty()) continue;
    const Vec2 p = rotate(l.point - centre, -drum_angle);
    const Vec2 force = rotate(l.force, -drum_angle) * (-1.0 / depth);
    const EdgePoint at = shell_[w] ? nearest_edge_point(*mesh_, ring_candidates(p), p)
                                   : nearest_edge_point(*mesh_, targets_[w], p);
    add_point_force(mesh_->loaded_edges[at.edge], at.xi, force, f);
    ++placed;
  }
  return placed;
}

}  // namespace dem2d
