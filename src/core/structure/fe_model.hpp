// The static finite-element model of the shell and its bars (docs/models.md, "The shell as finite
// elements"): the global stiffness and consistent mass assembled from the Q9 elements
// (core/structure/q9_element.hpp) over a mesh (core/structure/fe_mesh.hpp), the fixed degrees
// of freedom eliminated, and the free-free stiffness factorised once (sparse LDL^T); each solve
// is then a forward and back substitution. Units: m, N per metre of depth, Pa.
//
// Stress: at the Gauss points, and at the nodes (each element's Gauss values extrapolated to its
// nodes by the biquadratic through them, then averaged over the elements sharing the node).
// Per bar: the tip displacement is that of the top face's middle node (lateral offset 0), in
// the drum frame and resolved along the bar's side direction perp(radial) (counter-clockwise)
// and its radial direction; the peak von Mises stress of the bar is the largest over its
// elements' Gauss points. That peak depends on the mesh: the elastic stress is singular under a
// point force and at the feet, where the bar's sides meet the shell at a right angle (a
// re-entrant corner), and the peak grows there as the mesh is refined. bar_root gives a
// mesh-independent measure, the nominal stress at the bar's root.
#pragma once

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <array>
#include <cstddef>
#include <vector>

#include "core/structure/fe_mesh.hpp"
#include "core/structure/q9_element.hpp"

namespace dem2d {

using FeVector = Eigen::VectorXd;
using FeSparse = Eigen::SparseMatrix<double>;

struct FeStress {
  std::vector<std::array<PlaneStress, 9>> gauss;  // per element, see q9_gauss_stress
  std::vector<PlaneStress> nodal;                 // per node, averaged
};

struct BarResponse {
  Vec2 tip_displacement{};      // m, drum frame
  double tip_side = 0.0;        // m, along perp(radial): counter-clockwise positive
  double tip_radial = 0.0;      // m, along the bar's radial direction (outwards)
  double peak_von_mises = 0.0;  // Pa, over the bar's Gauss points
};

// The load a bar hands the shell at its feet, from statics: the resultant of the nodal loads on
// the bar's own nodes (not the feet), and its moment about the centre of the feet's chord
// (the bar's axis at FeBar::foot). The nominal root stress is the largest axial stress of a
// beam section of width w under them, |N| / w + 6 |M| / w^2: unlike the peak von Mises it does
// not depend on the mesh.
struct BarRoot {
  double axial = 0.0;   // N/m, along -radial (towards the centre): pulling the bar off the shell
  double shear = 0.0;   // N/m, along perp(radial)
  double moment = 0.0;  // N m/m, counter-clockwise
  double nominal_stress = 0.0;  // Pa
};

class FeModel {
 public:
  FeModel(FeMesh mesh, const ElasticMaterial& material);

  const FeMesh& mesh() const { return mesh_; }
  const ElasticMaterial& material() const { return material_; }
  std::size_t dofs() const { return mesh_.dofs(); }
  const FeSparse& stiffness() const { return k_; }  // every degree of freedom
  const FeSparse& mass() const { return m_; }
  // The free degrees of freedom, in order (the reduced system's unknowns).
  const std::vector<int>& free_dofs() const { return free_; }
  FeSparse reduced(const FeSparse& a) const;  // a's free-free block
  FeVector restrict_free(const FeVector& full) const;
  FeVector expand_free(const FeVector& reduced) const;  // zero on the fixed dofs

  // The displacement under nodal loads f (size dofs(); entries on fixed dofs ignored), the
  // fixed dofs held at zero, or at `prescribed`'s values.
  FeVector solve(const FeVector& f) const;
  FeVector solve(const FeVector& f, const FeVector& prescribed) const;
  // K u - f: the supports' reactions on the fixed dofs (zero elsewhere up to round-off).
  FeVector reactions(const FeVector& u, const FeVector& f) const;
  double strain_energy(const FeVector& u) const;  // u^T K u / 2, J per metre

  FeStress stress(const FeVector& u) const;
  BarResponse bar_response(std::size_t bar, const FeVector& u, const FeStress& s) const;
  // The same from the bar's own elements' stresses alone (the same values, without the rest of
  // the mesh's).
  BarResponse bar_response(std::size_t bar, const FeVector& u) const;
  // Element e's stresses at its Gauss points.
  std::array<PlaneStress, 9> gauss_stress(std::size_t e, const FeVector& u) const;
  BarRoot bar_root(std::size_t bar, const FeVector& f) const;

 private:
  Q9Nodes element_nodes(std::size_t e) const;
  FeMesh mesh_;
  ElasticMaterial material_;
  FeSparse k_, m_, k_free_fixed_;
  std::vector<int> free_, free_index_;  // free_index_: per dof its index in free_, or -1
  Eigen::SimplicialLDLT<FeSparse> k_free_;
};

}  // namespace dem2d
