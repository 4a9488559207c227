#include "core/structure/fe_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace dem2d {

FeModel::FeModel(FeMesh mesh, const ElasticMaterial& material)
    : mesh_(std::move(mesh)), material_(material) {
  const auto n = static_cast<Eigen::Index>(mesh_.dofs());
  if (mesh_.fixed.size() != mesh_.dofs())
    throw std::invalid_argument("FeModel: the mesh's fixed flags do not cover its dofs");
  const Eigen::Matrix3d d = plane_strain_elasticity(material_);
  std::vector<Eigen::Triplet<double>> kt, mt;
  kt.reserve(mesh_.elements.size() * 324);
  mt.reserve(mesh_.elements.size() * 324);
  for (std::size_t e = 0; e < mesh_.elements.size(); ++e) {
    const Q9Nodes x = element_nodes(e);
    const Q9Matrix ke = q9_stiffness(x, d);
    const Q9Matrix me = q9_mass(x, material_.density);
    const std::array<int, 9>& nodes = mesh_.elements[e];
    for (int a = 0; a < 18; ++a)
      for (int b = 0; b < 18; ++b) {
        const int r = 2 * nodes[a / 2] + a % 2, c = 2 * nodes[b / 2] + b % 2;
        kt.emplace_back(r, c, ke(a, b));
        mt.emplace_back(r, c, me(a, b));
      }
  }
  k_.resize(n, n);
  k_.setFromTriplets(kt.begin(), kt.end());
  m_.resize(n, n);
  m_.setFromTriplets(mt.begin(), mt.end());
  free_index_.assign(mesh_.dofs(), -1);
  for (std::size_t i = 0; i < mesh_.dofs(); ++i)
    if (!mesh_.fixed[i]) {
      free_index_[i] = static_cast<int>(free_.size());
      free_.push_back(static_cast<int>(i));
    }
  if (free_.empty()) throw std::invalid_argument("FeModel: every degree of freedom is fixed");
  // The free rows' couplings to every dof (the fixed columns give the prescribed values' load).
  std::vector<Eigen::Triplet<double>> ft;
  for (int c = 0; c < k_.outerSize(); ++c)
    for (FeSparse::InnerIterator it(k_, c); it; ++it)
      if (free_index_[static_cast<std::size_t>(it.row())] >= 0 &&
          mesh_.fixed[static_cast<std::size_t>(c)])
        ft.emplace_back(free_index_[static_cast<std::size_t>(it.row())], c, it.value());
  k_free_fixed_.resize(static_cast<Eigen::Index>(free_.size()), n);
  k_free_fixed_.setFromTriplets(ft.begin(), ft.end());
  k_free_.compute(reduced(k_));
  if (k_free_.info() != Eigen::Success)
    throw std::runtime_error("FeModel: the stiffness could not be factorised (a mechanism?)");
}

Q9Nodes FeModel::element_nodes(std::size_t e) const {
  Q9Nodes x{};
  for (int a = 0; a < 9; ++a) x[a] = mesh_.nodes[static_cast<std::size_t>(mesh_.elements[e][a])];
  return x;
}

FeSparse FeModel::reduced(const FeSparse& a) const {
  std::vector<Eigen::Triplet<double>> t;
  for (int c = 0; c < a.outerSize(); ++c) {
    const int fc = free_index_[static_cast<std::size_t>(c)];
    if (fc < 0) continue;
    for (FeSparse::InnerIterator it(a, c); it; ++it) {
      const int fr = free_index_[static_cast<std::size_t>(it.row())];
      if (fr >= 0) t.emplace_back(fr, fc, it.value());
    }
  }
  const auto n = static_cast<Eigen::Index>(free_.size());
  FeSparse r(n, n);
  r.setFromTriplets(t.begin(), t.end());
  return r;
}

FeVector FeModel::restrict_free(const FeVector& full) const {
  FeVector r(static_cast<Eigen::Index>(free_.size()));
  for (std::size_t i = 0; i < free_.size(); ++i) r(static_cast<Eigen::Index>(i)) = full(free_[i]);
  return r;
}

FeVector FeModel::expand_free(const FeVector& reduced) const {
  FeVector full = FeVector::Zero(static_cast<Eigen::Index>(mesh_.dofs()));
  for (std::size_t i = 0; i < free_.size(); ++i)
    full(free_[i]) = reduced(static_cast<Eigen::Index>(i));
  return full;
}

FeVector FeModel::solve(const FeVector& f) const {
  return expand_free(k_free_.solve(restrict_free(f)));
}

FeVector FeModel::solve(const FeVector& f, const FeVector& prescribed) const {
  FeVector fixed_values = prescribed;
  for (const int i : free_) fixed_values(i) = 0.0;
  const FeVector rhs = restrict_free(f) - k_free_fixed_ * fixed_values;
  FeVector u = expand_free(k_free_.solve(rhs));
  return u + fixed_values;
}

FeVector FeModel::reactions(const FeVector& u, const FeVector& f) const { return k_ * u - f; }

double FeModel::strain_energy(const FeVector& u) const { return 0.5 * u.dot(k_ * u); }

FeStress FeModel::stress(const FeVector& u) const {
  FeStress s;
  s.gauss.resize(mesh_.elements.size());
  s.nodal.assign(mesh_.nodes.size(), PlaneStress{});
  std::vector<int> count(mesh_.nodes.size(), 0);
  for (std::size_t e = 0; e < mesh_.elements.size(); ++e) {
    s.gauss[e] = gauss_stress(e, u);
    const std::array<PlaneStress, 9> at_nodes = q9_nodal_stress(s.gauss[e]);
    for (int a = 0; a < 9; ++a) {
      PlaneStress& n = s.nodal[static_cast<std::size_t>(mesh_.elements[e][a])];
      n.xx += at_nodes[a].xx;
      n.yy += at_nodes[a].yy;
      n.xy += at_nodes[a].xy;
      n.zz += at_nodes[a].zz;
      ++count[static_cast<std::size_t>(mesh_.elements[e][a])];
    }
  }
  for (std::size_t i = 0; i < s.nodal.size(); ++i) {
    const double w = count[i] > 0 ? 1.0 / count[i] : 0.0;
    s.nodal[i] = {w * s.nodal[i].xx, w * s.nodal[i].yy, w * s.nodal[i].xy, w * s.nodal[i].zz};
  }
  return s;
}

std::array<PlaneStress, 9> FeModel::gauss_stress(std::size_t e, const FeVector& u) const {
  Eigen::Matrix<double, 18, 1> ue;
  for (int a = 0; a < 9; ++a) {
    ue(2 * a) = u(2 * mesh_.elements[e][a]);
    ue(2 * a + 1) = u(2 * mesh_.elements[e][a] + 1);
  }
  return q9_gauss_stress(element_nodes(e), ue, material_);
}

BarResponse FeModel::bar_response(std::size_t bar, const FeVector& u) const {
  FeStress s;
  s.gauss.resize(mesh_.elements.size());
  for (const int e : mesh_.bars.at(bar).elements)
    s.gauss[static_cast<std::size_t>(e)] = gauss_stress(static_cast<std::size_t>(e), u);
  return bar_response(bar, u, s);
}

BarResponse FeModel::bar_response(std::size_t bar, const FeVector& u, const FeStress& s) const {
  const FeBar& b = mesh_.bars.at(bar);
  const Vec2 radial{std::cos(b.phi), std::sin(b.phi)};
  BarResponse r;
  r.tip_displacement = {u(2 * b.tip_node), u(2 * b.tip_node + 1)};
  r.tip_side = dot(r.tip_displacement, perp(radial));
  r.tip_radial = dot(r.tip_displacement, radial);
  for (const int e : b.elements)
    for (const PlaneStress& g : s.gauss[static_cast<std::size_t>(e)])
      r.peak_von_mises = std::max(r.peak_von_mises, g.von_mises());
  return r;
}

BarRoot FeModel::bar_root(std::size_t bar, const FeVector& f) const {
  const FeBar& b = mesh_.bars.at(bar);
  const Vec2 radial{std::cos(b.phi), std::sin(b.phi)};
  const Vec2 centre = b.foot * radial;
  Vec2 sum{};
  BarRoot r;
  for (const int n : b.nodes) {
    const Vec2 fn{f(2 * n), f(2 * n + 1)};
    sum += fn;
    r.moment += cross(mesh_.nodes[static_cast<std::size_t>(n)] - centre, fn);
  }
  r.axial = -dot(sum, radial);
  r.shear = dot(sum, perp(radial));
  const double w = 2.0 * b.half_width;
  r.nominal_stress = std::abs(r.axial) / w + 6.0 * std::abs(r.moment) / (w * w);
  return r;
}

}  // namespace dem2d
