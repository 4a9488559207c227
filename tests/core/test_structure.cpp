// The shell as finite elements (core/structure/): every test holds the model against a closed
// form. The patch test (constant strain on distorted, curved elements); a cantilever against
// the exact elasticity solution (Timoshenko and Goodier), its convergence and the absence of
// shear locking, and a clamped block against Timoshenko's beam; Lame's thick ring; the nodal
// loads of a point force and the supports' reactions; the wall-load records mapped to the mesh;
// Newmark's energy ledger and the cantilever's first frequency; a lifter bar of a whole drum
// against the cantilever formula.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "core/geometry/drum_geometry.hpp"
#include "core/structure/fe_dynamics.hpp"
#include "core/structure/fe_loads.hpp"
#include "core/structure/fe_mesh.hpp"
#include "core/structure/fe_model.hpp"

namespace dem2d {
namespace {

constexpr double kPi = std::numbers::pi;
const ElasticMaterial kSteel{200e9, 0.3, 7800.0};

double plane_strain_modulus(const ElasticMaterial& m) {
  return m.youngs_modulus / (1.0 - m.poisson_ratio * m.poisson_ratio);
}
double shear_modulus(const ElasticMaterial& m) {
  return m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio));
}

// ---------------------------------------------------------------------------------------------
// Patch test.

TEST(FiniteElementPatch, DistortedCurvedElementsReproduceALinearFieldAndConstantStress) {
  // 3 x 3 elements on the unit square, the interior nodes moved so that the elements are
  // distorted and their inner edges curved; the boundary stays the square's.
  const auto map = [](double a, double b) {
    const double bump = 0.12 * std::sin(kPi * a) * std::sin(kPi * b);
    return Vec2{a + bump * (1.0 + b), b + bump * (0.5 - a)};
  };
  FeMesh mesh = grid_mesh(3, 3, map);
  const int nx = 3, ny = 3;
  const auto exact = [](Vec2 x) {
    return Vec2{1e-3 + 2e-3 * x.x - 1e-3 * x.y, -5e-4 + 4e-4 * x.x + 3e-3 * x.y};
  };
  FeVector prescribed = FeVector::Zero(static_cast<Eigen::Index>(mesh.dofs()));
  for (int j = 0; j <= 2 * ny; ++j)
    for (int i = 0; i <= 2 * nx; ++i) {
      if (i != 0 && j != 0 && i != 2 * nx && j != 2 * ny) continue;
      const int n = grid_node(nx, i, j);
      mesh.fix_node(n);
      const Vec2 u = exact(mesh.nodes[static_cast<std::size_t>(n)]);
      prescribed(2 * n) = u.x;
      prescribed(2 * n + 1) = u.y;
    }
  const FeModel model(mesh, kSteel);
  const FeVector u =
      model.solve(FeVector::Zero(static_cast<Eigen::Index>(mesh.dofs())), prescribed);
  double du = 0.0;
  for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
    const Vec2 e = exact(mesh.nodes[n]);
    du = std::max(du, std::hypot(u(2 * n) - e.x, u(2 * n + 1) - e.y));
  }
  // eps_xx = 2e-3, eps_yy = 3e-3, gamma_xy = -1e-3 + 4e-4.
  const Eigen::Vector3d s = plane_strain_elasticity(kSteel) * Eigen::Vector3d{2e-3, 3e-3, -6e-4};
  const double sz = kSteel.poisson_ratio * (s(0) + s(1));
  const FeStress stress = model.stress(u);
  double ds = 0.0;
  for (const auto& element : stress.gauss)
    for (const PlaneStress& g : element)
      ds = std::max({ds, std::abs(g.xx - s(0)), std::abs(g.yy - s(1)), std::abs(g.xy - s(2)),
                     std::abs(g.zz - sz)});
  for (const PlaneStress& n : stress.nodal)
    ds = std::max({ds, std::abs(n.xx - s(0)), std::abs(n.yy - s(1)), std::abs(n.xy - s(2))});
  std::printf(
      "patch: max displacement error %.3e m (field ~3e-3 m), stress error %.3e (of %.3e Pa)\n", du,
      ds / s.norm(), s.norm());
  EXPECT_LT(du, 1e-14);
  EXPECT_LT(ds / s.norm(), 1e-12);
}

// ---------------------------------------------------------------------------------------------
// The cantilever: length L along x from the clamp (x = 0), depth D (y from -D/2 to D/2), a
// transverse load P (N/m) at x = L as the parabolic shear traction P / (2 I) (D^2 / 4 - y^2).
// The exact plane-stress solution (Timoshenko and Goodier) holds in plane strain with
// E' = E / (1 - nu^2) and nu' = nu / (1 - nu).
struct Cantilever {
  double length = 1.0, depth = 0.1, load = 1e5;
  ElasticMaterial material = kSteel;

  double e() const { return plane_strain_modulus(material); }
  double nu() const { return material.poisson_ratio / (1.0 - material.poisson_ratio); }
  double inertia() const { return depth * depth * depth / 12.0; }
  Vec2 exact(Vec2 x) const {
    const double c = load / (6.0 * e() * inertia()), d2 = depth * depth, l = length;
    return {-c * x.y * ((6.0 * l - 3.0 * x.x) * x.x + (2.0 + nu()) * (x.y * x.y - 0.25 * d2)),
            c * (3.0 * nu() * x.y * x.y * (l - x.x) + 0.25 * (4.0 + 5.0 * nu()) * d2 * x.x +
                 (3.0 * l - x.x) * x.x * x.x)};
  }
  // Timoshenko's beam: bending with E' plus shear with shear correction 5/6.
  double timoshenko_tip() const {
    return load * length * length * length / (3.0 * e() * inertia()) +
           load * length / (5.0 / 6.0 * shear_modulus(material) * depth);
  }
  FeMesh mesh(int nx, int ny) const {
    return grid_mesh(nx, ny, [this](double a, double b) {
      return Vec2{length * a, depth * (b - 0.5)};
    });
  }
  // The end load's nodal forces on the mesh's edge x = L.
  FeVector end_load(const FeMesh& m, int nx, int ny) const {
    FeVector f = FeVector::Zero(static_cast<Eigen::Index>(m.dofs()));
    const double q = load / (2.0 * inertia()), d2 = 0.25 * depth * depth;
    for (int j = 0; j < 2 * ny; j += 2) {
      const FeEdge edge{
          {grid_node(nx, 2 * nx, j), grid_node(nx, 2 * nx, j + 1), grid_node(nx, 2 * nx, j + 2)}};
      add_edge_traction(
          m, edge,
          [&](Vec2 x, Vec2) {
            return Vec2{0.0, q * (d2 - x.y * x.y)};
          },
          f);
    }
    return f;
  }
  // The FE tip deflection (x = L, y = 0): the clamp as the exact solution's displacements at
  // x = 0 (`exact_clamp`) or every node of x = 0 fixed.
  double fe_tip(int nx, int ny, bool exact_clamp, double* max_error = nullptr) const {
    FeMesh m = mesh(nx, ny);
    FeVector prescribed = FeVector::Zero(static_cast<Eigen::Index>(m.dofs()));
    for (int j = 0; j <= 2 * ny; ++j) {
      const int n = grid_node(nx, 0, j);
      m.fix_node(n);
      if (!exact_clamp) continue;
      const Vec2 u = exact(m.nodes[static_cast<std::size_t>(n)]);
      prescribed(2 * n) = u.x;
      prescribed(2 * n + 1) = u.y;
    }
    const FeModel model(m, material);
    const FeVector u = model.solve(end_load(m, nx, ny), prescribed);
    if (max_error) {
      *max_error = 0.0;
      for (std::size_t n = 0; n < m.nodes.size(); ++n) {
        const Vec2 e = exact(m.nodes[n]);
        *max_error = std::max(*max_error, std::hypot(u(2 * n) - e.x, u(2 * n + 1) - e.y));
      }
    }
    return u(2 * grid_node(nx, 2 * nx, ny) + 1);
  }
};

TEST(FiniteElementCantilever, ConvergesToTheExactElasticitySolution) {
  const Cantilever c{1.0, 0.2, 1e5, kSteel};
  const double exact_tip = c.exact({c.length, 0.0}).y;
  std::vector<double> tip_error, field_error;
  for (const int ny : {1, 2, 4}) {
    double e = 0.0;
    const double tip = c.fe_tip(5 * ny, ny, true, &e);
    tip_error.push_back(std::abs(tip - exact_tip) / exact_tip);
    field_error.push_back(e / exact_tip);
    std::printf("cantilever %2d x %d: tip error %.3e, largest nodal error %.3e (of the tip)\n",
                5 * ny, ny, tip_error.back(), field_error.back());
  }
  for (std::size_t k = 1; k < tip_error.size(); ++k) {
    const double rate = std::log2(field_error[k - 1] / field_error[k]);
    std::printf("  nodal error rate %.2f\n", rate);
    EXPECT_GT(rate, 2.8);  // quadratic elements: h^3 or better
  }
  EXPECT_LT(tip_error.back(), 1e-5);
}

TEST(FiniteElementCantilever, NoShearLockingAtSlenderness20WithOneElementThroughTheDepth) {
  const Cantilever c{2.0, 0.1, 1e4, kSteel};
  const double exact_tip = c.exact({c.length, 0.0}).y;
  const double tip = c.fe_tip(10, 1, true);  // elements twice as long as deep
  std::printf("slender cantilever (L/D = 20, 10 x 1): tip %.6e, exact %.6e, error %.2e\n", tip,
              exact_tip, (tip - exact_tip) / exact_tip);
  EXPECT_NEAR(tip / exact_tip, 1.0, 1e-3);
}

TEST(FiniteElementCantilever, AClampedLifterBlockBendsAsTimoshenkosBeam) {
  // A lifter-like block: L / D = 5 and 10, every node of the foot fixed.
  for (const double slenderness : {5.0, 10.0}) {
    const Cantilever c{0.1 * slenderness, 0.1, 1e4, kSteel};
    const double tip = c.fe_tip(4 * static_cast<int>(slenderness), 4, false);
    const double beam = c.timoshenko_tip();
    std::printf("clamped block L/D = %.0f: FE tip %.6e, Timoshenko %.6e, ratio %.4f\n", slenderness,
                tip, beam, tip / beam);
    EXPECT_NEAR(tip / beam, 1.0, slenderness < 6.0 ? 0.03 : 0.01);
  }
}

}  // namespace
}  // namespace dem2d
