// The shell of a run (deck table [shell], docs/models.md "The shell as finite elements"): the
// drum's ring and lifter bars meshed once (core/structure/fe_mesh.hpp) with the shell's
// material, the stiffness factorised once, and at each moment asked the quasi-static response
// to the charge's wall loads of that moment. The ring is clamped on its outer surface and meshed
// in the drum frame, where its stiffness does not change as the drum turns; the charge sees the
// rigid drum (one-way coupling).
//
// Per bar, against the wall loads of lifters.csv (core/geometry/lifter_loads.hpp):
//   tip_deflection  the top face's middle node displaced against the drum's sense of rotation
//                   (along -tangential: the way the charge pushes a lifting face), m;
//   peak_von_mises  the largest von Mises stress over the bar's Gauss points, Pa (it grows as
//                   the mesh is refined under point forces and at the feet' corners);
//   root_stress     the nominal stress of the bar's root section from statics, |N| / w +
//                   6 |M| / w^2, Pa (it does not depend on the mesh).
// The records must come in (particle id, element) order so that the response is the same bits
// on any rank count.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "core/base/scene.hpp"
#include "core/geometry/wall_loads.hpp"
#include "core/geometry/walls.hpp"
#include "core/structure/fe_loads.hpp"
#include "core/structure/fe_model.hpp"

namespace dem2d {

struct ShellBar {
  double tip_deflection = 0.0;  // m
  double peak_von_mises = 0.0;  // Pa
  double root_stress = 0.0;     // Pa
};

struct ShellResponse {
  std::vector<ShellBar> bars;  // the drum's bars, in order
  std::size_t records = 0;     // the wall load records placed on the mesh
  Vec2 applied{};              // the sum of the records' loads on the walls / depth, drum frame
  Vec2 nodal{};                // the sum of the nodal loads, N/m
  Vec2 reaction{};             // with `check`: the sum of the supports' reactions, N/m (= -nodal)
  double max_displacement = 0.0;  // the largest nodal displacement, m
};

// The shell's state under a moment's wall loads, node by node (FeMesh::nodes' order), in the
// lab frame at the walls' pose of that moment: the drum-frame mesh turned by the drum's angle
// about its centre.
struct ShellField {
  std::vector<Vec2> position;      // the nodes' rest positions, m
  std::vector<Vec2> displacement;  // m
  std::vector<double> von_mises;   // the nodal (averaged, FeStress::nodal) von Mises stress, Pa
};

class Shell {
 public:
  // Throws std::invalid_argument when the scene's drum cannot be meshed (a polygon).
  Shell(const Scene& scene, const Walls& walls);

  // The response to `records` (a moment's wall loads of every rank, in key order) at the walls'
  // current pose; `check`: also the supports' reactions (a product with the whole stiffness,
  // as long as the solve itself).
  ShellResponse respond(std::span<const WallLoad> records, const Walls& walls,
                        bool check = false) const;

  // The displacement and nodal stress of every node under `records` (as respond()'s).
  ShellField field(std::span<const WallLoad> records, const Walls& walls) const;

  const FeModel& model() const { return model_; }
  double depth() const { return depth_; }

 private:
  // The records' loads on the mesh's nodes at the walls' pose; `placed`: how many were placed.
  FeVector nodal_loads(std::span<const WallLoad> records, const Walls& walls,
                       std::size_t* placed) const;
  FeModel model_;
  WallLoadMap map_;
  Vec2 centre_{};
  double depth_ = 0.0;
  double sense_ = 1.0;  // +1: the drum turns counter-clockwise
};

}  // namespace dem2d
