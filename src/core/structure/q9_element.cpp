#include "core/structure/q9_element.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace dem2d {
namespace {

// Local node a at (kXi[a], kEta[a]) in {-1, 0, 1} as indices 0, 1, 2 of lagrange3.
constexpr std::array<int, 9> kXi{0, 2, 2, 0, 1, 2, 1, 0, 1};
constexpr std::array<int, 9> kEta{0, 0, 2, 2, 0, 1, 2, 1, 1};

// The Jacobian's inverse transpose applied to the reference derivatives: the shape functions'
// (x, y) derivatives at (xi, eta), and det J.
double cartesian_derivatives(const Q9Nodes& x, double xi, double eta, std::array<Vec2, 9>& dn) {
  const std::array<Vec2, 9> dr = q9_shape_derivatives(xi, eta);
  double j11 = 0.0, j12 = 0.0, j21 = 0.0, j22 = 0.0;  // d(x, y) / d(xi, eta)
  // Every product rounded on its own (rounded(), core/base/vec2.hpp): the vectorizer would fuse
  // these 2 x 2 sums into multiply-add-subtract instructions despite -ffp-contract=off.
  for (int a = 0; a < 9; ++a) {
    j11 += rounded(dr[a].x * x[a].x);
    j12 += rounded(dr[a].x * x[a].y);
    j21 += rounded(dr[a].y * x[a].x);
    j22 += rounded(dr[a].y * x[a].y);
  }
  const double det = rounded(j11 * j22) - rounded(j12 * j21);
  if (!(det > 0.0))
    throw std::runtime_error("q9 element: non-positive Jacobian (a folded or clockwise element)");
  for (int a = 0; a < 9; ++a)
    dn[a] = {(rounded(j22 * dr[a].x) - rounded(j12 * dr[a].y)) / det,
             (rounded(j11 * dr[a].y) - rounded(j21 * dr[a].x)) / det};
  return det;
}

Eigen::Matrix<double, 3, 18> strain_matrix(const std::array<Vec2, 9>& dn) {
  Eigen::Matrix<double, 3, 18> b = Eigen::Matrix<double, 3, 18>::Zero();
  for (int a = 0; a < 9; ++a) {
    b(0, 2 * a) = dn[a].x;
    b(1, 2 * a + 1) = dn[a].y;
    b(2, 2 * a) = dn[a].y;
    b(2, 2 * a + 1) = dn[a].x;
  }
  return b;
}

}  // namespace

double PlaneStress::von_mises() const {
  const double s = xx * xx + yy * yy + zz * zz - xx * yy - yy * zz - zz * xx + 3.0 * xy * xy;
  return std::sqrt(std::max(s, 0.0));
}

std::array<double, 3> lagrange3(double t) {
  return {0.5 * t * (t - 1.0), (1.0 - t) * (1.0 + t), 0.5 * t * (t + 1.0)};
}

std::array<double, 3> lagrange3_derivative(double t) { return {t - 0.5, -2.0 * t, t + 0.5}; }

std::array<double, 9> q9_shape(double xi, double eta) {
  const std::array<double, 3> lx = lagrange3(xi), ly = lagrange3(eta);
  std::array<double, 9> n{};
  for (int a = 0; a < 9; ++a) n[a] = lx[kXi[a]] * ly[kEta[a]];
  return n;
}

std::array<Vec2, 9> q9_shape_derivatives(double xi, double eta) {
  const std::array<double, 3> lx = lagrange3(xi), ly = lagrange3(eta);
  const std::array<double, 3> dx = lagrange3_derivative(xi), dy = lagrange3_derivative(eta);
  std::array<Vec2, 9> d{};
  for (int a = 0; a < 9; ++a) d[a] = {dx[kXi[a]] * ly[kEta[a]], lx[kXi[a]] * dy[kEta[a]]};
  return d;
}

Eigen::Matrix3d plane_strain_elasticity(const ElasticMaterial& m) {
  const double nu = m.poisson_ratio;
  const double c = m.youngs_modulus / ((1.0 + nu) * (1.0 - 2.0 * nu));
  Eigen::Matrix3d d;
  d << c * (1.0 - nu), c * nu, 0.0, c * nu, c * (1.0 - nu), 0.0, 0.0, 0.0,
      c * 0.5 * (1.0 - 2.0 * nu);
  return d;
}

Q9Matrix q9_stiffness(const Q9Nodes& x, const Eigen::Matrix3d& d) {
  Q9Matrix k = Q9Matrix::Zero();
  std::array<Vec2, 9> dn{};
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      const double det = cartesian_derivatives(x, kGauss3[i], kGauss3[j], dn);
      const Eigen::Matrix<double, 3, 18> b = strain_matrix(dn);
      k += (kGauss3Weight[i] * kGauss3Weight[j] * det) * (b.transpose() * (d * b));
    }
  return k;
}

Q9Matrix q9_mass(const Q9Nodes& x, double density) {
  Q9Matrix m = Q9Matrix::Zero();
  std::array<Vec2, 9> dn{};
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      const double det = cartesian_derivatives(x, kGauss3[i], kGauss3[j], dn);
      const std::array<double, 9> n = q9_shape(kGauss3[i], kGauss3[j]);
      const double w = kGauss3Weight[i] * kGauss3Weight[j] * det * density;
      for (int a = 0; a < 9; ++a)
        for (int b = 0; b < 9; ++b) {
          const double v = w * n[a] * n[b];
          m(2 * a, 2 * b) += v;
          m(2 * a + 1, 2 * b + 1) += v;
        }
    }
  return m;
}

std::array<PlaneStress, 9> q9_gauss_stress(const Q9Nodes& x, const Eigen::Matrix<double, 18, 1>& u,
                                           const ElasticMaterial& m) {
  const Eigen::Matrix3d d = plane_strain_elasticity(m);
  std::array<PlaneStress, 9> out{};
  std::array<Vec2, 9> dn{};
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      cartesian_derivatives(x, kGauss3[i], kGauss3[j], dn);
      const Eigen::Vector3d s = d * (strain_matrix(dn) * u);
      out[3 * j + i] = {s(0), s(1), s(2), m.poisson_ratio * (s(0) + s(1))};
    }
  return out;
}

std::array<PlaneStress, 9> q9_nodal_stress(const std::array<PlaneStress, 9>& gauss) {
  // Node coordinate -1, 0, 1 in units of the Gauss abscissa: -1/g, 0, 1/g.
  const double g = kGauss3[2];
  const std::array<double, 3> at{-1.0 / g, 0.0, 1.0 / g};
  std::array<PlaneStress, 9> out{};
  for (int a = 0; a < 9; ++a) {
    const std::array<double, 3> lx = lagrange3(at[kXi[a]]), ly = lagrange3(at[kEta[a]]);
    PlaneStress s;
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        const double w = lx[i] * ly[j];
        const PlaneStress& q = gauss[3 * j + i];
        s.xx += w * q.xx;
        s.yy += w * q.yy;
        s.xy += w * q.xy;
        s.zz += w * q.zz;
      }
    out[a] = s;
  }
  return out;
}

}  // namespace dem2d
