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
#include <limits>
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

// ---------------------------------------------------------------------------------------------
// Lame's thick ring: inner radius a, outer b clamped (u_r(b) = 0), pressure p inside. Plane
// strain: u_r = A r + B / r, sigma_r = 2 (lambda + mu) A - 2 mu B / r^2,
// sigma_theta = 2 (lambda + mu) A + 2 mu B / r^2, with B = -A b^2 and sigma_r(a) = -p.
struct LameRing {
  double a = 1.0, b = 1.2, p = 1e6;
  ElasticMaterial m = kSteel;
  double lambda() const {
    const double nu = m.poisson_ratio;
    return m.youngs_modulus * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  }
  double big_a() const {
    const double mu = shear_modulus(m);
    return -p / (2.0 * (lambda() + mu) + 2.0 * mu * b * b / (a * a));
  }
  double u(double r) const { return big_a() * (r - b * b / r); }
  double sigma_r(double r) const {
    return 2.0 * (lambda() + shear_modulus(m)) * big_a() +
           2.0 * shear_modulus(m) * big_a() * b * b / (r * r);
  }
  double sigma_theta(double r) const {
    return 2.0 * (lambda() + shear_modulus(m)) * big_a() -
           2.0 * shear_modulus(m) * big_a() * b * b / (r * r);
  }
};

TEST(FiniteElementLame, AClampedThickRingUnderInternalPressureConverges) {
  const LameRing ring;
  std::vector<double> u_error;
  for (const int nr : {1, 2, 4}) {
    const ShellMeshSpec spec{ring.b - ring.a, nr, 2.0 * (ring.b - ring.a) / nr, true};
    const FeModel model(shell_mesh(ring.a, {}, spec), ring.m);
    FeVector f = FeVector::Zero(static_cast<Eigen::Index>(model.dofs()));
    add_inner_pressure(model.mesh(), ring.p, f);
    const FeVector u = model.solve(f);
    const FeStress s = model.stress(u);
    double du = 0.0, dsr = 0.0, dst = 0.0;
    for (std::size_t n = 0; n < model.mesh().nodes.size(); ++n) {
      const Vec2 x = model.mesh().nodes[n];
      const double r = norm(x);
      const Vec2 e = x * (1.0 / r);
      du = std::max(du, std::abs(u(2 * n) * e.x + u(2 * n + 1) * e.y - ring.u(r)));
      const PlaneStress& q = s.nodal[n];
      const double sr = q.xx * e.x * e.x + q.yy * e.y * e.y + 2.0 * q.xy * e.x * e.y;
      const double st = q.xx * e.y * e.y + q.yy * e.x * e.x - 2.0 * q.xy * e.x * e.y;
      dsr = std::max(dsr, std::abs(sr - ring.sigma_r(r)));
      dst = std::max(dst, std::abs(st - ring.sigma_theta(r)));
    }
    u_error.push_back(du / ring.u(ring.a));
    std::printf(
        "Lame ring n_r = %d (%zu elements): u_r error %.3e, sigma_r %.3e, sigma_theta %.3e "
        "(of p)\n",
        nr, model.mesh().elements.size(), u_error.back(), dsr / ring.p, dst / ring.p);
    EXPECT_LT(dsr / ring.p, 0.02);
    EXPECT_LT(dst / ring.p, 0.02);
  }
  EXPECT_LT(u_error.back(), 1e-5);
  for (std::size_t k = 1; k < u_error.size(); ++k)
    EXPECT_GT(std::log2(u_error[k - 1] / u_error[k]), 2.8);
}

// ---------------------------------------------------------------------------------------------
// The drum: radius 1 m, a shell 50 mm thick, 8 bars 150 mm high and 50 mm wide.
DrumSpec eight_lifter_drum(double width = 0.05) {
  DrumSpec d;
  d.present = true;
  d.radius = 1.0;
  d.angle = 0.0;
  d.material = "steel";
  LifterSpec l;
  l.count = 8;
  l.height = 0.15;
  l.width = width;
  l.angle = 0.1;
  d.lifters.push_back(l);
  return d;
}
const ShellMeshSpec kShell{0.05, 2, 0.0125, true};

TEST(ShellMesh, BarsStandOnRingNodesAndTheMeshHoldsTheDrumsArea) {
  const DrumGeometry drum(eight_lifter_drum());
  const FeMesh mesh = shell_mesh(drum, kShell);
  const auto has_node = [&](Vec2 p) {
    double d = 1e300;
    for (const Vec2 x : mesh.nodes) d = std::min(d, norm(x - p));
    return d;
  };
  double corner = 0.0;
  for (const DrumGeometry::Bar& b : drum.bars())
    for (const Vec2 c : b.corner) corner = std::max(corner, has_node(c));
  EXPECT_LT(corner, 1e-14);
  // The area: the ring, plus per bar the rectangle from its top to the chord of its feet and
  // the circular segment between the chord and the circle.
  const double r = drum.radius(), t = kShell.thickness;
  const DrumGeometry::Bar& b = drum.bars().front();
  const double half = std::asin(b.half_width / r),
               foot = std::sqrt(r * r - b.half_width * b.half_width);
  const double bar =
      2.0 * b.half_width * (foot - b.top) + r * r * (half - std::sin(half) * std::cos(half));
  const double area = kPi * ((r + t) * (r + t) - r * r) + 8.0 * bar;
  const FeModel model(mesh, {1.0, 0.3, 1.0});
  double mass = 0.0;  // the x-x block of the consistent mass, summed: density 1 times the area
  for (int c = 0; c < model.mass().outerSize(); c += 2)
    for (FeSparse::InnerIterator it(model.mass(), c); it; ++it)
      if (it.row() % 2 == 0) mass += it.value();
  std::printf("drum mesh: %zu nodes, %zu elements; area %.12f, closed form %.12f (%.1e)\n",
              mesh.nodes.size(), mesh.elements.size(), mass, area, mass / area - 1.0);
  EXPECT_NEAR(mass / area, 1.0, 1e-7);
  EXPECT_EQ(mesh.bars.size(), 8u);
}

TEST(ShellMesh, APolygonalShellAndOverlappingBarsAreRefused) {
  DrumSpec polygon = eight_lifter_drum();
  polygon.sides = 12;
  EXPECT_THROW(shell_mesh(DrumGeometry(polygon), kShell), std::invalid_argument);
  std::vector<FeBar> bars(2);
  bars[0].half_width = bars[1].half_width = 0.05;
  bars[0].top = bars[1].top = 0.8;
  bars[1].phi = 0.06;  // the feet span +-0.05 rad
  EXPECT_THROW(shell_mesh(1.0, bars, kShell), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Loads.

TEST(ShellLoads, APointForceGivesNodalLoadsWithItsSumAndItsMomentAndTheSupportsCarryIt) {
  const DrumGeometry drum(eight_lifter_drum());
  const FeModel model(shell_mesh(drum, kShell), kSteel);
  const FeMesh& mesh = model.mesh();
  const auto n = static_cast<Eigen::Index>(model.dofs());
  const auto sum_and_moment = [&](const FeVector& f, Vec2& sum, double& moment) {
    sum = {};
    moment = 0.0;
    for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
      const Vec2 fi{f(2 * i), f(2 * i + 1)};
      sum += fi;
      moment += cross(mesh.nodes[i], fi);
    }
  };
  // A weight resting on the shell (on the circle, between bars) and a push on a bar's face.
  const double theta = -0.5 * kPi + 0.3;
  const Vec2 on_shell{std::cos(theta), std::sin(theta)};
  const DrumGeometry::Bar& bar = drum.bars()[2];
  const Vec2 on_face = 0.6 * bar.corner[2] + 0.4 * bar.corner[3];
  for (const auto& [p, force] :
       {std::pair{on_shell, Vec2{0.0, -2500.0}}, std::pair{on_face, Vec2{-1200.0, 700.0}}}) {
    FeVector f = FeVector::Zero(n);
    add_point_force(mesh, p, force, f);
    Vec2 sum;
    double moment = 0.0;
    sum_and_moment(f, sum, moment);
    const double scale = norm(force) * norm(p);
    std::printf("point force at (%.3f, %.3f): sum error %.1e N, moment error %.1e (of |F||p|)\n",
                p.x, p.y, norm(sum - force), std::abs(moment - cross(p, force)) / scale);
    EXPECT_LT(norm(sum - force), 1e-15 * norm(force) * 4.0);
    // The arc's quadratic edges lie within R theta^4 / 32 = 5e-11 m of the circle here.
    EXPECT_LT(std::abs(moment - cross(p, force)) / scale, 1e-9);
    const FeVector u = model.solve(f);
    const FeVector r = model.reactions(u, f);
    Vec2 reaction;
    double reaction_moment = 0.0;
    sum_and_moment(r, reaction, reaction_moment);
    double free_residual = 0.0;
    for (const int i : model.free_dofs()) free_residual = std::max(free_residual, std::abs(r(i)));
    std::printf("  supports: sum + F = %.1e N, moment + M = %.1e N m, free-dof residual %.1e N\n",
                norm(reaction + force), std::abs(reaction_moment + moment), free_residual);
    EXPECT_LT(norm(reaction + force), 1e-9 * norm(force));
    EXPECT_LT(std::abs(reaction_moment + moment), 1e-9 * scale);
  }
}

TEST(ShellLoads, WallLoadRecordsLandOnTheirElementsInTheDrumFrame) {
  const DrumGeometry drum(eight_lifter_drum());
  const FeMesh mesh = shell_mesh(drum, kShell);
  // The walls' elements: the circle, three per bar in order, and a [[wall]] segment.
  std::vector<WallElement> elements(1 + 3 * drum.bars().size() + 1);
  elements[0].kind = WallKind::kCircle;
  elements[0].part = WallPart::kShell;
  for (std::size_t k = 1; k + 1 < elements.size(); ++k) elements[k].part = WallPart::kLifter;
  elements.back().part = WallPart::kWall;
  const WallLoadMap map(mesh, elements);
  const double angle = 0.7, depth = 0.25;
  const Vec2 centre{0.3, -0.2};
  const auto lab = [&](Vec2 drum_point) { return centre + rotate(drum_point, angle); };
  const DrumGeometry::Bar& bar = drum.bars()[5];
  const Vec2 on_face = 0.3 * bar.corner[2] + 0.7 * bar.corner[3];  // bar 5's lifting face
  const Vec2 on_top = 0.5 * bar.corner[1] + 0.5 * bar.corner[2];
  const Vec2 on_shell{std::cos(-1.9), std::sin(-1.9)};
  std::vector<WallLoad> loads(4);
  loads[0] = {1 + 3 * 5 + 2, 0, lab(on_face), {30.0, -5.0}, 0.0, {}};
  loads[1] = {0, 1, lab(on_shell), {-3.0, 40.0}, 0.0, {}};
  loads[2] = {1 + 3 * 5 + 1, 2, lab(on_top), {1.0, 2.0}, 0.0, {}};
  loads[3] = {static_cast<std::int32_t>(elements.size() - 1), 3, {5.0, 5.0}, {9.0, 9.0}, 0.0, {}};
  FeVector f = FeVector::Zero(static_cast<Eigen::Index>(mesh.dofs()));
  EXPECT_EQ(map.add(loads, angle, centre, depth, f), 3u);
  // The same forces placed directly in the drum frame: the wall receives -force / depth.
  FeVector g = FeVector::Zero(f.size());
  const std::array<Vec2, 3> at{on_face, on_shell, on_top};
  Vec2 total{};
  for (int k = 0; k < 3; ++k) {
    const Vec2 force = rotate(loads[static_cast<std::size_t>(k)].force, -angle) * (-1.0 / depth);
    add_point_force(mesh, at[static_cast<std::size_t>(k)], force, g);
    total += force;
  }
  Vec2 sum{};
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) sum += Vec2{f(2 * i), f(2 * i + 1)};
  std::printf("wall loads: |f - direct| = %.1e, sum error %.1e N/m\n", (f - g).norm(),
              norm(sum - total));
  EXPECT_LT((f - g).norm(), 1e-12 * g.norm());
  EXPECT_LT(norm(sum - total),
            1e-12 * norm(total));  // The shell's records, found by angle, land where the nearest of
                                   // all edges is: points all
  // round the exposed circle (not under a bar's foot).
  std::vector<WallLoad> shell;
  for (int k = 0; k < 97; ++k) {
    const double a = 2.0 * kPi * k / 97.0 + 0.013;
    const bool under_a_bar =
        std::any_of(drum.bars().begin(), drum.bars().end(), [&](const auto& b) {
          return std::abs(std::remainder(a - b.phi, 2.0 * kPi)) <= std::asin(b.half_width);
        });
    if (!under_a_bar) shell.push_back({0, k, lab({std::cos(a), std::sin(a)}), {0.0, 1.0}, 0.0, {}});
  }
  FeVector by_angle = FeVector::Zero(f.size()), nearest = FeVector::Zero(f.size());
  EXPECT_EQ(map.add(shell, angle, centre, depth, by_angle), shell.size());
  for (const WallLoad& l : shell)
    add_point_force(mesh, rotate(l.point - centre, -angle),
                    rotate(l.force, -angle) * (-1.0 / depth), nearest);
  std::printf("  %zu shell records by angle against the nearest edge: %.1e\n", shell.size(),
              (by_angle - nearest).norm());
  EXPECT_LT((by_angle - nearest).norm(), 1e-12 * nearest.norm());
}

// ---------------------------------------------------------------------------------------------
// A whole drum: a load on one bar's lifting face, at its top, pushing against the rotation.

TEST(ShellDrum, ALoadOnALiftingFaceBendsThatBarAsACantileverOnAnElasticFoot) {
  const DrumGeometry drum(eight_lifter_drum());
  const FeModel model(shell_mesh(drum, kShell), kSteel);
  const std::size_t loaded = 3;
  const DrumGeometry::Bar& bar = drum.bars()[loaded];
  const Vec2 radial{std::cos(bar.phi), std::sin(bar.phi)};
  const double p = 1e4;  // N/m
  FeVector f = FeVector::Zero(static_cast<Eigen::Index>(model.dofs()));
  add_point_force(model.mesh(), bar.corner[2], -p * perp(radial), f);
  const FeVector u = model.solve(f);
  const FeStress s = model.stress(u);
  const BarResponse r = model.bar_response(loaded, u, s);
  // The cantilever from the shell's surface (its mid-width) to the top face.
  const double length = drum.radius() - bar.top, w = 2.0 * bar.half_width;
  const double inertia = w * w * w / 12.0;
  const double beam =
      p * length * length * length / (3.0 * plane_strain_modulus(kSteel) * inertia) +
      p * length / (5.0 / 6.0 * shear_modulus(kSteel) * w);
  // The root bending stress of the beam, 6 P L / w^2, for the peak von Mises' order.
  const double root = 6.0 * p * length / (w * w);
  std::printf(
      "drum bar: tip %.4e m (side), %.2e m (radial); cantilever %.4e m; ratio %.3f; peak "
      "von Mises %.3e Pa, beam root stress %.3e Pa\n",
      r.tip_side, r.tip_radial, beam, -r.tip_side / beam, r.peak_von_mises, root);
  EXPECT_LT(r.tip_side, 0.0);          // along the load
  EXPECT_GT(-r.tip_side / beam, 1.1);  // the foot is not rigid: the shell adds compliance
  EXPECT_LT(-r.tip_side / beam, 1.5);
  // The root's resultants from statics: the load's moment about the feet's chord centre.
  const BarRoot at_root = model.bar_root(loaded, f);
  const Vec2 force = -p * perp(radial);
  const double arm = dot(bar.corner[3], radial);
  const double moment = cross(bar.corner[2] - arm * radial, force);
  const double nominal = 6.0 * std::abs(moment) / (w * w);
  std::printf(
      "  root: axial %.2e N/m, shear %.6e N/m, moment %.6e N m/m (statics %.6e), nominal "
      "stress %.6e Pa (%.6e)\n",
      at_root.axial, at_root.shear, at_root.moment, moment, at_root.nominal_stress, nominal);
  EXPECT_NEAR(at_root.shear, -p, 1e-12 * p);
  EXPECT_NEAR(at_root.axial, 0.0, 1e-12 * p);
  EXPECT_NEAR(at_root.moment, moment, 1e-12 * std::abs(moment));
  EXPECT_NEAR(at_root.nominal_stress, nominal, 1e-12 * nominal);
  // Half way up the bar the bending stress along it is the beam's, +-6 P a / w^2 on the faces
  // at a distance a from the load (the lifting face, +w/2, on the convex side: in tension);
  // the moment there is set by the load alone, whatever the foot does.
  const double mid = bar.top + 0.5 * (dot(bar.corner[3], radial) - bar.top);
  for (const double lateral : {-bar.half_width, bar.half_width}) {
    std::size_t best = 0;
    double best_d = 1e300;
    for (std::size_t i = 0; i < model.mesh().nodes.size(); ++i) {
      const Vec2 x = model.mesh().nodes[i];
      const double d = std::abs(dot(x, perp(radial)) - lateral) + std::abs(dot(x, radial) - mid);
      if (d < best_d) best_d = d, best = i;
    }
    const Vec2 x = model.mesh().nodes[best];
    const PlaneStress& q = s.nodal[best];
    const double along =
        q.xx * radial.x * radial.x + q.yy * radial.y * radial.y + 2.0 * q.xy * radial.x * radial.y;
    const double expected =
        (lateral > 0.0 ? 1.0 : -1.0) * 6.0 * p * (dot(x, radial) - bar.top) / (w * w);
    std::printf("  bending stress at mid-height, lateral %+.3f m: %.4e Pa, beam %.4e Pa\n", lateral,
                along, expected);
    EXPECT_LT(best_d, 1e-12);
    EXPECT_NEAR(along / expected, 1.0, 0.02);
  }
  // The same bar with the whole ring held fixed (the bar clamped on its foot arc) bends as the
  // cantilever: the shell's compliance is what the first ratio adds.
  FeMesh rigid_ring = model.mesh();
  for (std::size_t e = 0; e < rigid_ring.elements.size(); ++e)
    if (rigid_ring.element_bar[e] < 0)
      for (const int n : rigid_ring.elements[e]) rigid_ring.fix_node(n);
  const FeModel clamped(rigid_ring, kSteel);
  const FeVector uc = clamped.solve(f);
  const double clamped_tip = clamped.bar_response(loaded, uc, clamped.stress(uc)).tip_side;
  std::printf("  the bar clamped on a rigid ring: tip %.4e m, ratio to the cantilever %.3f\n",
              clamped_tip, -clamped_tip / beam);
  EXPECT_NEAR(-clamped_tip / beam, 1.0, 0.03);
  // The other bars barely move.
  for (std::size_t b = 0; b < model.mesh().bars.size(); ++b) {
    if (b == loaded) continue;
    EXPECT_LT(std::abs(model.bar_response(b, u, s).tip_side), 0.01 * beam);
  }
}

TEST(ShellDrum, TheBarsTipConvergesWithTheMeshWhileThePeakStressAtItsCornersGrows) {
  const DrumGeometry drum(eight_lifter_drum());
  const DrumGeometry::Bar& bar = drum.bars()[3];
  const Vec2 radial{std::cos(bar.phi), std::sin(bar.phi)};
  std::vector<double> tip, peak;
  for (const int nr : {1, 2, 4}) {
    const FeModel model(shell_mesh(drum, {0.05, nr, 0.025 / nr, true}), kSteel);
    FeVector f = FeVector::Zero(static_cast<Eigen::Index>(model.dofs()));
    add_point_force(model.mesh(), bar.corner[2], -1e4 * perp(radial), f);
    const FeVector u = model.solve(f);
    const BarResponse r = model.bar_response(3, u, model.stress(u));
    tip.push_back(r.tip_side);
    peak.push_back(r.peak_von_mises);
    std::printf(
        "drum bar, element size %.5f m (%zu elements): tip %.6e m, peak von Mises %.4e Pa\n",
        0.025 / nr, model.mesh().elements.size(), r.tip_side, r.peak_von_mises);
  }
  // The tip converges, at about first order (the singular corners set the rate); the peak von
  // Mises, at a point force or a re-entrant foot, does not.
  const double shrink = (tip[2] - tip[1]) / (tip[1] - tip[0]);
  const double extrapolated = tip[2] + (tip[2] - tip[1]) * shrink / (1.0 - shrink);
  std::printf("  successive tip differences shrink by %.2f; extrapolated tip %.6e m\n", shrink,
              extrapolated);
  EXPECT_GT(shrink, 0.0);
  EXPECT_LT(shrink, 0.6);
  EXPECT_NEAR(tip[1] / extrapolated, 1.0, 0.03);  // the mesh of the test above
  EXPECT_GT(peak[2], peak[1]);
  EXPECT_GT(peak[1], peak[0]);
}

// ---------------------------------------------------------------------------------------------
// Dynamics: a cantilever L = 1 m, D = 50 mm (L/D = 20), released from its static deflection
// under a tip load. The first frequency of the Euler-Bernoulli beam (plane strain: E'):
// omega_1 = 1.8751^2 sqrt(E' I / (rho A L^4)).

struct Vibration {
  Cantilever beam{1.0, 0.05, 1e3, kSteel};
  int nx = 20, ny = 2;
  FeModel model() const {
    FeMesh m = beam.mesh(nx, ny);
    for (int j = 0; j <= 2 * ny; ++j) m.fix_node(grid_node(nx, 0, j));
    return FeModel(m, beam.material);
  }
  double omega() const {
    const double k = 1.87510407;
    return k * k *
           std::sqrt(beam.e() * beam.inertia() /
                     (beam.material.density * beam.depth * std::pow(beam.length, 4)));
  }
  int tip() const { return 2 * grid_node(nx, 2 * nx, ny) + 1; }
};

// The round-off of evaluating u^T A u: the machine epsilon times sum |A_ij u_i u_j| / |u^T A u|
// (the cancellation in the sum; about 1e-10 relative for the strain energy of a bent beam,
// whose stiffness couples nodes with opposite forces far larger than the net).
double quadratic_round_off(const FeSparse& a, const FeVector& u) {
  double sum = 0.0;
  for (int c = 0; c < a.outerSize(); ++c)
    for (FeSparse::InnerIterator it(a, c); it; ++it)
      sum += std::abs(it.value() * u(it.row()) * u(c));
  return std::numeric_limits<double>::epsilon() * sum / std::abs(u.dot(a * u));
}

TEST(FiniteElementDynamics, NewmarkConservesTheEnergyOfAFreeVibrationAndGivesTheFirstFrequency) {
  const Vibration v;
  const FeModel model = v.model();
  const FeVector load = v.beam.end_load(model.mesh(), v.nx, v.ny);
  const FeVector u0 = model.solve(load);
  const FeVector zero = FeVector::Zero(u0.size());
  const double period = 2.0 * kPi / v.omega();
  FeDynamics dyn(model, period / 200.0);
  dyn.start(u0, zero, zero);
  const double e0 = dyn.kinetic_energy() + dyn.strain_energy();
  const double round_off = quadratic_round_off(model.stiffness(), u0);
  double drift = 0.0, per_step = 0.0, before = e0, last = u0(v.tip()), last_time = 0.0;
  std::vector<double> crossings;  // downward zero crossings of the tip
  for (int k = 0; k < 1000; ++k) {
    dyn.step(zero);
    const double e = dyn.kinetic_energy() + dyn.strain_energy();
    drift = std::max(drift, std::abs(e - e0) / e0);
    per_step = std::max(per_step, std::abs(e - before) / e0);
    before = e;
    const double tip = dyn.displacement()(v.tip());
    if (last > 0.0 && tip <= 0.0)
      crossings.push_back(last_time + (dyn.time() - last_time) * last / (last - tip));
    last = tip;
    last_time = dyn.time();
  }
  ASSERT_GE(crossings.size(), 4u);
  const double measured = (crossings.back() - crossings.front()) / (crossings.size() - 1.0);
  std::printf(
      "free vibration: energy change %.1e per step at most, %.1e over 1000 steps (the "
      "strain energy's round-off %.1e); period %.6e s, beam %.6e s (%+.2f %%)\n",
      per_step, drift, round_off, measured, period, 100.0 * (measured / period - 1.0));
  EXPECT_LT(per_step, round_off);
  EXPECT_LT(drift, 3.0 * round_off);
  // Shear and rotary inertia lengthen the period of an L/D = 20 beam by a few tenths of a per
  // cent; Newmark's period error at 200 steps a period is (omega h)^2 / 12 = 8e-5.
  EXPECT_NEAR(measured / period, 1.0, 0.01);
  EXPECT_GT(measured, period);
}

TEST(FiniteElementDynamics,
     TheLedgerOfAForcedDampedVibrationClosesAndItSettlesOnTheStaticSolution) {
  const Vibration v;
  const FeModel model = v.model();
  const FeVector load = v.beam.end_load(model.mesh(), v.nx, v.ny);
  const FeVector zero = FeVector::Zero(load.size());
  const double period = 2.0 * kPi / v.omega();
  // Rayleigh damping of about 5 % of critical at the first frequency (mass part alone).
  FeDynamics dyn(model, period / 50.0, {0.1 * v.omega(), 1e-6});
  dyn.start(zero, zero, zero);
  double ledger = 0.0, per_step = 0.0, before = 0.0;
  for (int k = 0; k < 2000; ++k) {
    dyn.step(load);  // suddenly applied at t = 0
    const double e = dyn.kinetic_energy() + dyn.strain_energy();
    const double error = e + dyn.dissipated() - dyn.work();
    ledger = std::max(ledger, std::abs(error) / dyn.work());
    per_step = std::max(per_step, std::abs(error - before) / dyn.work());
    before = error;
  }
  const FeVector static_u = model.solve(load);
  const double stat = static_u(v.tip());
  const double round_off = quadratic_round_off(model.stiffness(), static_u);
  const double tip = dyn.displacement()(v.tip());
  std::printf(
      "damped forced vibration: ledger error %.1e of the work per step at most, %.1e over "
      "2000 steps (the strain energy's round-off %.1e); tip %.6e, static %.6e\n",
      per_step, ledger, round_off, tip, stat);
  EXPECT_LT(per_step, round_off);
  EXPECT_LT(ledger, 3.0 * round_off);
  EXPECT_NEAR(tip / stat, 1.0, 1e-3);
}

}  // namespace
}  // namespace dem2d
