// A plane-strain finite-element mesh of the drum's shell ring and its lifter bars, in the drum
// frame (relative to the drum's centre, turning with the drum; docs/models.md, "The shell as
// finite elements").
//
// Elements are 9-node quadratic quadrilaterals (core/structure/q9_element.hpp), nodes in the
// order: corners (-1,-1), (1,-1), (1,1), (-1,1), mid-sides of the edges eta = -1, xi = 1,
// eta = 1, xi = -1, then the centre. Every mesh here is structured: a grid of (2 nx + 1) x
// (2 ny + 1) nodes per block, each element taking a 3 x 3 block of them.
//
// The shell: a ring from the drum's radius R (its inner surface, the DEM's circle) to R + t,
// n_r elements through the thickness, its outer surface clamped. The angular divisions are
// chosen so that every bar's feet (the points where its sides meet the circle, at phi +-
// asin(w / 2R)) are ring nodes: the arc under a bar and each arc between two bars are divided
// evenly, into ceil(arc / element size) elements. A bar is meshed on the ring's inner nodes
// under it: its columns run parallel to the bar's axis from each foot node on the circle to
// the straight top face (the node of lateral offset s on the circle maps to the top face's
// point of the same offset), so bar and ring share nodes (a conforming mesh). Only the circular
// shell is meshed; a polygonal shell (sides >= 3) is refused.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <vector>

#include "core/base/vec2.hpp"
#include "core/geometry/drum_geometry.hpp"

namespace dem2d {

// A quadratic boundary edge: its end nodes node[0], node[2] and its middle node node[1].
struct FeEdge {
  std::array<int, 3> node{};
  int bar = -1;   // -1: the shell's inner surface; else the bar (into FeMesh::bars)
  int face = -1;  // a bar's face as the walls number them: 0 foot-to-top at lateral -w/2,
                  // 1 the top face, 2 top-to-foot at lateral +w/2 (DrumGeometry::Bar::corner)
};

// One lifter bar of the mesh, as DrumGeometry describes it (the drum frame).
struct FeBar {
  double phi = 0.0;            // its radial direction, rad
  double half_width = 0.0;     // m
  double top = 0.0;            // the top face's distance from the centre, m
  std::vector<int> elements;   // into FeMesh::elements
  std::vector<int> top_nodes;  // the top face's nodes, from lateral -w/2 to +w/2
  int tip_node = -1;           // the top face's middle node (lateral offset 0)
  std::vector<int> nodes;      // its own nodes: all but the feet (those are the ring's)
  double foot = 0.0;           // the feet's distance from the centre along the bar's axis
};

struct FeMesh {
  std::vector<Vec2> nodes;                   // m, drum frame
  std::vector<std::array<int, 9>> elements;  // Q9 node order, counter-clockwise
  std::vector<int> element_bar;              // per element: its bar, or -1 (the ring, a block)
  std::vector<FeEdge> loaded_edges;          // the exposed inner surface: ring and bar faces
  std::vector<char> fixed;                   // per degree of freedom 2 node + (0 x, 1 y)
  std::vector<FeBar> bars;

  std::size_t dofs() const { return 2 * nodes.size(); }
  void fix_node(int node) { fixed[2 * node] = fixed[2 * node + 1] = 1; }
};

struct ShellMeshSpec {
  double thickness = 0.0;  // m, the shell ring's radial thickness t
  int elements_through_thickness = 2;
  double element_size = 0.0;  // m, the target edge length along the shell and the bars
  bool clamp_outer = true;    // the outer surface fixed
};

// The shell ring of inner radius `radius` with `bars` standing on it (each bar's feet on the
// circle; bars whose foot arcs overlap are refused).
FeMesh shell_mesh(double radius, const std::vector<FeBar>& bars, const ShellMeshSpec& spec);
// The drum's shell and bars (DrumGeometry::bars(), in that order). Throws std::invalid_argument
// for a polygonal shell.
FeMesh shell_mesh(const DrumGeometry& drum, const ShellMeshSpec& spec);

// A structured mesh of nx x ny elements on the image of the unit square under `map` (a node at
// grid parameters (a, b) in [0, 1]^2 stands at map(a, b)); nothing fixed, no loaded edges.
// `map` must keep the orientation (counter-clockwise elements).
FeMesh grid_mesh(int nx, int ny, const std::function<Vec2(double, double)>& map);
// The node of a grid_mesh at grid index (i, j), 0 <= i <= 2 nx, 0 <= j <= 2 ny.
inline int grid_node(int nx, int i, int j) { return j * (2 * nx + 1) + i; }

}  // namespace dem2d
