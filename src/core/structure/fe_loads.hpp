// Loads on the finite-element shell (docs/models.md, "The shell as finite elements"): forces
// and tractions on the mesh's exposed inner surface turned into nodal loads, N per metre of
// depth, in the drum frame.
//
// A point force at a point of a boundary edge (quadratic, 3 nodes) is shared among the edge's
// nodes by the edge's shape functions at the point: N_a(xi) F. They sum to one (partition of
// unity), so the nodal loads sum to F up to the round-off of three additions, and sum_a N_a(xi)
// x_a = x(xi) is the point itself, so their moment about the centre is x(xi) x F: the force's
// moment, where x(xi) is the point of the edge nearest to the given one (on a straight edge the
// point itself; the quadratic arc of a ring element spanning an angle 2 theta departs from the
// circle by at most R theta^4 / 32, 5e-11 m for 12.5 mm elements on a 1 m drum).
//
// The DEM's wall loads (core/geometry/wall_loads.hpp) are forces of 3D spheres on the walls:
// the FE model carries per metre of depth, so a record's load on the shell is
// -force / depth (the record's force acts on the particle), the depth being the slice of mill
// the 2D charge stands for. Each record is placed by its wall element: a lifter element
// (WallPart::kLifter; the walls hold three per bar, consecutive, in the bars' order, faces as
// DrumGeometry::Bar::corner runs) goes to that bar's face, the shell's circle to the nearest
// edge of the ring's exposed inner surface; [[wall]] segments are not part of the drum and are
// skipped (the ring's edges are found by the point's angle, a bar face's among its few edges by
// distance). Points are taken from the lab frame to the drum frame by the drum's current angle:
// x_drum = rotate(x_lab - centre, -angle), and so are forces. The records are added in the
// order given: pass them sorted by (particle id, element) for sums that do not depend on the
// rank count.
#pragma once

#include <cstddef>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include "core/geometry/wall_loads.hpp"
#include "core/geometry/walls.hpp"
#include "core/structure/fe_model.hpp"

namespace dem2d {

// The point of a set of edges nearest to p: the edge (into FeMesh::loaded_edges), its
// parameter xi in [-1, 1] (node[0] at -1, node[2] at +1) and the distance.
struct EdgePoint {
  std::size_t edge = 0;
  double xi = 0.0;
  double distance = 0.0;
};
EdgePoint nearest_edge_point(const FeMesh& mesh, std::span<const std::size_t> edges, Vec2 p);
// The point x(xi) of a quadratic edge.
Vec2 edge_point(const FeMesh& mesh, const FeEdge& edge, double xi);

// Adds force F (N/m) at parameter xi of `edge` to f (size mesh.dofs()).
void add_point_force(const FeEdge& edge, double xi, Vec2 force, FeVector& f);
// Adds force F (N/m) at the point of the exposed inner surface nearest to p (drum frame).
void add_point_force(const FeMesh& mesh, Vec2 p, Vec2 force, FeVector& f);
// Adds the consistent nodal loads of a traction t(x, n) (Pa = N/m per m of edge; n the edge's
// unit normal pointing to the right of node[0] -> node[2]) along `edge`, 3 Gauss points.
void add_edge_traction(const FeMesh& mesh, const FeEdge& edge,
                       const std::function<Vec2(Vec2, Vec2)>& traction, FeVector& f);
// Adds a pressure p (Pa) on every exposed inner edge, pushing outwards from the drum's inside.
void add_inner_pressure(const FeMesh& mesh, double pressure, FeVector& f);

// The wall elements' places on the mesh, for the DEM's wall load records.
class WallLoadMap {
 public:
  // `elements`: Walls::elements(). The mesh's bars must be the drum's, in order (shell_mesh of
  // the same DrumGeometry), three lifter elements per bar. The map keeps a reference to `mesh`
  // (FeModel::mesh(), say), which must outlive it.
  WallLoadMap(const FeMesh& mesh, std::span<const WallElement> elements);
  // Adds each record's load on the walls (-force / depth, N/m) to f, in the records' order.
  // `drum_angle`: the drum's current angle (Walls::drum_angle()); `centre`: the drum's centre,
  // lab frame; `depth`: the slice depth, m. Returns the number of records placed.
  std::size_t add(std::span<const WallLoad> loads, double drum_angle, Vec2 centre, double depth,
                  FeVector& f) const;

  // The ring's exposed edges near drum-frame point p: the edge whose angular span holds p's
  // angle (or the next one counter-clockwise, when p stands over a bar's foot) and its two
  // neighbours.
  std::vector<std::size_t> ring_candidates(Vec2 p) const;

 private:
  const FeMesh* mesh_;
  std::vector<std::vector<std::size_t>> targets_;     // per wall element its bar face's edges
  std::vector<char> shell_;                           // per wall element: the shell's circle
  std::vector<std::pair<double, std::size_t>> ring_;  // exposed ring edges by start angle
};

}  // namespace dem2d
