// The 9-node quadratic quadrilateral (Lagrange, isoparametric) in plane strain, linear elastic,
// per metre of depth. Chosen because it does not lock: its displacement holds every complete
// quadratic and x^2 y, x y^2, x^2 y^2, so the linear bending stress of a thin wall or a short
// lifter bar is represented with one element through the depth, and with 3 x 3 Gauss points
// (full integration) it has no spurious zero-energy modes; being isoparametric it represents any
// linear displacement field exactly on curved and distorted elements (the patch test).
//
// Node order (FeMesh): corners (-1,-1), (1,-1), (1,1), (-1,1); mid-sides (0,-1), (1,0), (0,1),
// (-1,0); centre (0,0). Degrees of freedom 2 a + (0 x, 1 y) for local node a.
//
// Plane strain: eps_zz = 0, sigma_zz = nu (sigma_xx + sigma_yy); the elasticity matrix is
// E / ((1 + nu)(1 - 2 nu)) [[1 - nu, nu, 0], [nu, 1 - nu, 0], [0, 0, (1 - 2 nu) / 2]] on
// (eps_xx, eps_yy, gamma_xy). Stiffness K_e = int B^T D B dA and consistent mass
// M_e = rho int N^T N dA (both 3 x 3 Gauss: exact for the mass of a parallelogram element).
#pragma once

#include <Eigen/Dense>
#include <array>

#include "core/base/vec2.hpp"

namespace dem2d {

struct ElasticMaterial {
  double youngs_modulus = 0.0;  // Pa
  double poisson_ratio = 0.0;
  double density = 0.0;  // kg/m^3
};

using Q9Matrix = Eigen::Matrix<double, 18, 18>;
using Q9Nodes = std::array<Vec2, 9>;

// The plane-strain stress at a point: the in-plane components, sigma_zz and von Mises.
struct PlaneStress {
  double xx = 0.0, yy = 0.0, xy = 0.0, zz = 0.0;
  double von_mises() const;
};

// The Gauss points of the 3 x 3 rule along one direction and their weights.
inline constexpr std::array<double, 3> kGauss3{-0.7745966692414834, 0.0, 0.7745966692414834};
inline constexpr std::array<double, 3> kGauss3Weight{5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};

// The quadratic Lagrange functions of one variable at nodes -1, 0, 1, and their derivatives.
std::array<double, 3> lagrange3(double t);
std::array<double, 3> lagrange3_derivative(double t);
// The 9 shape functions and their (xi, eta) derivatives at (xi, eta).
std::array<double, 9> q9_shape(double xi, double eta);
std::array<Vec2, 9> q9_shape_derivatives(double xi, double eta);

Eigen::Matrix3d plane_strain_elasticity(const ElasticMaterial& m);
Q9Matrix q9_stiffness(const Q9Nodes& x, const Eigen::Matrix3d& d);
Q9Matrix q9_mass(const Q9Nodes& x, double density);
// The stress at the 9 Gauss points (index 3 j + i for xi = kGauss3[i], eta = kGauss3[j]) from
// the element's nodal displacements; and extrapolated to the 9 nodes (the biquadratic through
// the Gauss values, evaluated at the nodes).
std::array<PlaneStress, 9> q9_gauss_stress(const Q9Nodes& x, const Eigen::Matrix<double, 18, 1>& u,
                                           const ElasticMaterial& m);
std::array<PlaneStress, 9> q9_nodal_stress(const std::array<PlaneStress, 9>& gauss);

}  // namespace dem2d
