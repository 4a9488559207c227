// The names in snapshots.h5 (the layout snapshots.hpp describes) that both of its writers use:
// the HDF5 side (snapshots.cpp) writes the groups and datasets, the XDMF sidecar (xdmf.cpp)
// points at them. Internal to the snapshot writer.
#pragma once

#include <fmt/format.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace dem2d::snapshot_layout {

// The groups of snapshots.h5: complete snapshots, their wall outlines, the particles' outlines
// (scenes with shaped particles only), the XDMF helpers.
inline const std::string kSnapshotsGroup = "/snapshots";
inline const std::string kWallsGroup = "/walls";
inline const std::string kOutlinesGroup = "/outlines";
inline const std::string kXdmfGroup = "/xdmf";
// The shell's finite elements (runs with a [shell] only): its state at each snapshot, and its
// mesh, the same for the whole run, once per file.
inline const std::string kShellGroup = "/shell";
inline const std::string kShellMeshGroup = "/shell_mesh";
// The mesh's datasets: its 9-node elements, each element's bar, and the split of each element
// into four 4-node quadrilaterals that snapshots.xmf draws (with each quadrilateral's bar).
inline const std::string kShellElements = kShellMeshGroup + "/elements";
inline const std::string kShellElementBar = kShellMeshGroup + "/element_bar";
inline const std::string kShellQuadrilaterals = kShellMeshGroup + "/quadrilaterals";
inline const std::string kShellQuadrilateralBar = kShellMeshGroup + "/quadrilateral_bar";

// The dataset that gives the XDMF grids their geometry; every other one is a point attribute.
inline constexpr const char* kGeometry = "position";
// The points of each particle's outline polygon (core/shape/outline.hpp) in a snapshot of a
// scene with shaped particles: /outlines/NNNNNN/points holds N x kOutlineVertices rows.
inline constexpr std::uint64_t kOutlineVertices = 24;
// The registry field of material rows: its datasets carry the material names (attribute names).
inline constexpr const char* kMaterial = "material";

// The dataset holding 0, 1, ..., n - 1: the connectivity of a Polyvertex topology of n points.
// The Xdmf3 readers make no cells without it (the points would not show as a surface).
inline std::string polyvertex_dataset(std::uint64_t n) {
  return fmt::format("/xdmf/polyvertex_{}", n);
}

// The dataset holding the connectivity of n polygons of k points each, numbered one after the
// other: row i is i k, i k + 1, ..., i k + k - 1 (the outlines' Polygon topology).
inline std::string polygon_dataset(std::uint64_t k, std::uint64_t n) {
  return fmt::format("/xdmf/polygon_{}_{}", k, n);
}

// "0=steel,1=iron ore": each material's row of /materials and its name (the `names` attribute
// of a snapshot's material dataset; the XDMF domain's material_names).
inline std::string material_lookup(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t k = 0; k < names.size(); ++k)
    out += fmt::format("{}{}={}", k == 0 ? "" : ",", k, names[k]);
  return out;
}

}  // namespace dem2d::snapshot_layout
