// SnapshotWriter: the particle snapshots of a run, DIR/snapshots.h5, with an XDMF sidecar
// DIR/snapshots.xmf that opens them in ParaView (docs/output.md).
//
// Layout of snapshots.h5:
//   /materials/{name, density, youngs_modulus, poisson_ratio, shear_modulus, restitution,
//               damping_normal, damping_tangential, sliding_friction, rolling_friction,
//               normal_stiffness}        one row per material, in deck order
//   /snapshots/NNNNNN                    one group per write(), NNNNNN = 000000, 000001, ...
//       attributes time (double, s), step (int64)
//       one dataset per particle field marked `snapshot` in the store's registry
//       (core/shape/particles.hpp: id, material, position, velocity, angle, spin, radius), named as
//       the field, N rows (N x 2 for a Vec2), with string attributes `unit` and `doc` from the
//       field's FieldMeta (`material` also `names`, "0=steel,1=ore"); then `speed` (|velocity|,
//       m/s); then any extra fields. The group tracks the creation order of its datasets
//       (resume() reads them back in that order). Only per-particle datasets: post/*.py and
//       the tests read every member as N rows. A field marked `stable` (id, material, radius)
//       whose rows on every rank are those it stored last is not stored again: the member is a
//       hard link to the stored dataset (one object, two names; readers see no difference).
//   /walls/NNNNNN                        the wall outline at snapshot NNNNNN's time, when write()
//                                        was given one: attributes time, step;
//       points   (M x 2 double, m)       the outline's points in the lab frame
//       segments (S x 2 int64)           the straight pieces, as pairs of rows of `points`
//                                        each a hard link to the last stored one when equal to
//                                        it (the segments of a scene: always; the points: while
//                                        the walls stand still)
//   /outlines/NNNNNN                     scenes with shaped particles (ParticleStore::shaped())
//                                        and N > 0 only: attributes time, step;
//       points   (N K x 2 float, m)      K = snapshot_layout::kOutlineVertices points of each
//                                        particle's curve (core/shape/outline.hpp), lab frame,
//                                        rows i K .. i K + K - 1 the particle of row i
//   /shell/NNNNNN                        runs with a [shell] only, when write() was given one:
//                                        attributes time, step;
//       points   (M x 2 double, m)       the mesh's nodes at rest, lab frame (turned with the drum)
//       displacement (M x 2 double, m)   the nodes' displacement, lab frame
//       von_mises (M double, Pa)         the nodal von Mises stress
//   /shell_mesh                          the mesh, once per file (the first snapshot with a shell):
//       elements (E x 9 int64)           the 9-node elements as rows of the shell's points
//       element_bar (E int64)            each element's bar, -1 for the ring
//       quadrilaterals (4 E x 4 int64)   each element as four 4-node quadrilaterals over its
//                                        nodes (snapshots.xmf's topology), rows 4 e .. 4 e + 3
//       quadrilateral_bar (4 E int64)    each quadrilateral's bar
//   /incomplete/NNNNNN, /incomplete/walls_NNNNNN, /incomplete/outlines_NNNNNN,
//   /incomplete/shell_NNNNNN             the snapshot being written and its outlines (staging);
//                                        empty between writes, except after a failed write
//   /xdmf/polyvertex_N                   int64 0..N-1, the connectivity snapshots.xmf uses for
//                                        its Polyvertex topology (one per particle count N)
//   /xdmf/polygon_K_N                    int64 N x K, row i: i K .. i K + K - 1, the
//                                        connectivity of the outlines' Polygon topology
// N is the global number of owned particles; rank 0's particles come first, then rank 1's...
//
// Complete or absent. write() opens the file (MPI-IO, collectively), builds the snapshot in
// /incomplete/NNNNNN and its outlines in /incomplete/walls_NNNNNN and outlines_NNNNNN, moves
// the outlines' links to /walls/NNNNNN and /outlines/NNNNNN and the snapshot's to /snapshots/NNNNNN
// (H5Lmove: no data is copied) and closes the file, which writes out all of its metadata; only then
// does rank 0 list the snapshot in snapshots.xmf. Between writes the file is closed and whole, so a
// run killed then leaves every listed snapshot readable. A write that fails part-way (disk full)
// leaves at most partial groups under /incomplete, never under /snapshots: everything under
// /snapshots is a complete snapshot. Readers (post/*.py) list /snapshots only. Syncing to disk
// (fsync) is what a snapshot would otherwise cost most: write() syncs both files (H5Fflush before
// the close, then snapshots.xmf and the folder) only when kSyncInterval of wall time (rank 0's
// clock) has passed since the last sync, and close() syncs them at the end.
//
// snapshots.xmf (XDMF 3): a temporal collection with, per snapshot, a spatial collection at its
// time of up to four grids: "particles", a Polyvertex grid with XY geometry from position,
// every other dataset as a point attribute (a Vec2 field, e.g. velocity, as a 2-component
// Vector) and one field-data value "material: NAME" (its row) per material; "outlines" (when
// the snapshot has /outlines), a Polygon grid of one K-node cell per particle with every
// dataset of the snapshot as a cell attribute and the same field data; "walls", the outline
// as a Polyline grid of 2-node segments (absent when the snapshot has none); and "shell" (when
// the snapshot has one), a Quadrilateral grid over /shell/NNNNNN/points with the displacement
// (Vector) and von Mises as point attributes and the bar as a cell attribute. The domain's
// <Information Name="material_names" Value="0=steel,1=ore"/> names the materials too. Checked
// with ParaView 5.11's "XDMF Reader" and "Xdmf3 Reader S/T" (the shell grid: against the HDF5
// file by tests/io/check_xdmf.py only). It lists exactly the snapshots
// under /snapshots, and only after they are there. Rank 0 creates it whole with the first
// snapshot (through a temporary file and a rename); each later snapshot costs O(1): its <Grid>
// and the fixed closing trailer (</Grid></Domain></Xdmf>) overwrite the old trailer in place,
// so the file is a valid XDMF document at every moment but during that one small write.
// resume() regenerates it whole (temporary file and rename). The .xmf text and file are
// xdmf.hpp's (XdmfSidecar); the names both files use, snapshot_layout.hpp's.
//
// Every member is collective over the communicator. A failure throws IoError with the same
// message on every rank.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/base/scene.hpp"
#include "core/base/vec2.hpp"
#include "core/shape/particles.hpp"
#include "io/hdf5.hpp"
#include "parallel/comm.hpp"

namespace dem2d {

class XdmfSidecar;  // xdmf.hpp

// A per-particle field that is not in the store's registry, written after the registry's:
// one value per owned particle, in the store's order. Names must be the same on all ranks and
// differ from the registry's snapshot fields.
struct ExtraField {
  std::string name;
  std::span<const double> values;
  std::string unit = "1";
  std::string doc{};
};

// One per-particle dataset of a snapshot group.
struct SnapshotDataset {
  std::string name;     // the field's name
  std::string type;     // "int64", "int32" or "double" (little-endian in the file)
  std::size_t columns;  // 1, or 2 for a Vec2 field (an N x 2 dataset)
  std::string unit;     // the `unit` attribute
  std::string doc;      // the `doc` attribute
};

// The datasets every snapshot of `particles` holds: the registry's fields marked `snapshot`,
// in registry order, then the derived `speed`. Throws std::logic_error for a marked field of a
// type it cannot write.
std::vector<SnapshotDataset> snapshot_datasets(const ParticleStore& particles);

// What the writer knows of one snapshot of the file.
// The shell's finite elements at a snapshot (core/structure/shell.hpp's ShellField and the
// mesh, core/structure/fe_mesh.hpp): per node its position, displacement and von Mises stress,
// and the mesh's elements. Rank 0's is written.
struct ShellSnapshot {
  std::span<const Vec2> position;                // the nodes at rest, lab frame, m
  std::span<const Vec2> displacement;            // lab frame, m
  std::span<const double> von_mises;             // Pa
  std::span<const std::array<int, 9>> elements;  // Q9 node order, counter-clockwise
  std::span<const int> element_bar;              // per element: its bar, or -1 (the ring)
};

struct SnapshotInfo {
  std::string name;  // NNNNNN: the group is /snapshots/NNNNNN
  double time = 0.0;
  std::int64_t step = 0;
  std::uint64_t particles = 0;            // N, all ranks
  std::vector<SnapshotDataset> datasets;  // in the group's order: registry fields, speed, extras
  std::uint64_t wall_points = 0;          // M: rows of /walls/NNNNNN/points
  std::uint64_t wall_segments = 0;        // S: rows of /walls/NNNNNN/segments; 0: no outline
  // K: the points of each particle's outline, /outlines/NNNNNN/points holding N K rows; 0: no
  // outlines (a scene without shaped particles, or no particles)
  std::uint64_t outline_vertices = 0;
  std::uint64_t shell_nodes = 0;     // rows of /shell/NNNNNN/points; 0: no shell
  std::uint64_t shell_elements = 0;  // rows of /shell_mesh/elements (9-node elements)
};

class SnapshotWriter {
 public:
  // Creates (truncating) DIR/snapshots.h5 with the /materials table, and removes a stale
  // DIR/snapshots.xmf. Throws IoError "cannot create DIR/snapshots.h5: REASON" on every rank
  // when it cannot.
  SnapshotWriter(MPI_Comm comm, const std::string& directory,
                 const std::vector<MaterialSpec>& materials);

  // Continues the snapshots of an interrupted run, for a restart from a checkpoint at `time`.
  // When DIR/snapshots.h5 exists, opens it read-write (MPI-IO, collectively), keeps its
  // /materials (`materials` is not used: snapshots.xmf names the file's /materials/name),
  // deletes every /snapshots group whose `time` attribute is > time + tolerance (the
  // interrupted run wrote it after the checkpoint), every staging group under /incomplete, the
  // /xdmf/polyvertex_N and polygon_K_N no kept snapshot uses, the /walls/NNNNNN, /outlines/NNNNNN
  // and /shell/NNNNNN of no kept snapshot (and /shell_mesh when no kept snapshot has a shell);
  // keeps the rest, numbers the next snapshot after the highest kept one, regenerates snapshots.xmf
  // (temporary file and rename) to list exactly the kept snapshots (removes it when none is kept),
  // and appends in O(1) from there. When DIR/snapshots.h5 does not exist, it is the constructor
  // above. Throws IoError on every rank, with the same message naming the file, when the file
  // cannot be opened ("cannot open DIR/snapshots.h5: REASON") or is not a snapshot file
  // ("DIR/snapshots.h5: cannot ...").
  static std::unique_ptr<SnapshotWriter> resume(MPI_Comm comm, const std::string& directory,
                                                const std::vector<MaterialSpec>& materials,
                                                double time, double tolerance);

  ~SnapshotWriter();  // closes the file; never throws
  SnapshotWriter(const SnapshotWriter&) = delete;
  SnapshotWriter& operator=(const SnapshotWriter&) = delete;

  // Writes the owned particles [0, n_owned()) as the next snapshot, with the wall outline
  // `walls` (polylines in the lab frame at `time`, e.g. core/geometry/walls.hpp's wall_outlines;
  // rank 0's are written, every rank passes the same; none: no /walls group, no "walls" grid):
  // /incomplete/NNNNNN and /incomplete/walls_NNNNNN, moved to /walls/NNNNNN and
  // /snapshots/NNNNNN, the file closed; then rank 0 appends its grid to snapshots.xmf. After a
  // failed write (IoError) the writer may write again: the next write first removes what the failed
  // one left and reuses its number if it did not reach /snapshots.
  // With `shell` (rank 0's is written; the other ranks may pass null), the shell's state as
  // /shell/NNNNNN (staged as /incomplete/shell_NNNNNN) and, with the first such snapshot of the
  // file, its mesh as /shell_mesh; rank 0 passing null: no shell in this snapshot.
  void write(const ParticleStore& particles, double time, std::int64_t step,
             std::span<const std::vector<Vec2>> walls = {}, std::span<const ExtraField> extra = {},
             const ShellSnapshot* shell = nullptr);

  // Syncs snapshots.h5, snapshots.xmf and the folder to disk and reports a failure (the
  // destructor neither syncs nor reports). Later writes are errors.
  void close();

  const std::string& h5_path() const { return h5_path_; }
  const std::string& xdmf_path() const;
  // The snapshots under /snapshots: those a resume kept and those written since.
  std::size_t snapshots_written() const { return written_; }
  // The last of them (std::nullopt while there is none). The writer keeps no other record of
  // the snapshots before it: its memory does not grow with their number.
  const std::optional<SnapshotInfo>& last_snapshot() const { return last_; }

  // Testing only (tests/io): the next write() throws IoError on every rank, as a full disk
  // would, just before it writes dataset number `datasets` (0: the first) of its staging
  // group (snapshot_datasets, then the extra fields), or, when the snapshot has no more
  // datasets than that, after the last one and the wall outline (before the moves); the message
  // ends in "injected failure". It costs a write nothing when not armed. Collective: call it on
  // every rank.
  void fail_before_dataset_for_testing(std::size_t datasets) { fail_before_dataset_ = datasets; }

 private:
  struct NoFile {};  // the constructors' common part: the paths, no file opened yet
  struct WallData;   // an outline as written: points and segments
  // A dataset stored only when it changes (a stable field, the wall outline's points and
  // segments): its published name and this rank's rows and bytes, as last stored.
  struct Stored {
    std::string path;
    h5::RowRange rows;
    std::vector<std::byte> bytes;
  };
  static WallData wall_data(std::span<const std::vector<Vec2>> outlines);
  SnapshotWriter(NoFile, MPI_Comm comm, const std::string& directory);
  SnapshotInfo describe(const ParticleStore& p, double time, std::int64_t step,
                        std::span<const ExtraField> extra) const;
  void write_materials(const std::vector<MaterialSpec>& materials);
  void clear_failed_write(const std::string& name);
  void stage(const std::string& group, const SnapshotInfo& record, const h5::RowRange& rows,
             const ParticleStore& p, std::span<const ExtraField> extra, const WallData& walls,
             const ShellSnapshot* shell);
  std::optional<std::vector<SnapshotInfo>> publish(const SnapshotInfo& record, bool sync);
  bool link_if_unchanged(const std::string& key, const std::string& staged,
                         const std::string& published, const h5::RowRange& rows, const void* data,
                         std::size_t bytes);
  std::vector<SnapshotInfo> published_records() const;
  void read_walls(SnapshotInfo& record) const;
  void sync_due(std::array<int, 6>& header);
  void write_datasets(const std::string& group, const std::string& published,
                      const h5::RowRange& rows, const ParticleStore& p,
                      std::span<const ExtraField> extra);
  void write_polyvertex(const h5::RowRange& rows);
  void write_outlines(const std::string& group, const SnapshotInfo& record,
                      const h5::RowRange& rows, const ParticleStore& p);
  void write_polygons(std::uint64_t vertices, const h5::RowRange& rows);
  void write_walls(const std::string& group, const SnapshotInfo& record, const WallData& walls);
  void write_shell(const std::string& group, const SnapshotInfo& record,
                   const ShellSnapshot* shell);
  void write_shell_mesh(const SnapshotInfo& record, const ShellSnapshot* shell);
  void reconcile_shell(std::vector<SnapshotInfo>& kept);
  void read_shell(SnapshotInfo& record) const;
  void agree(const std::string& local_error);                 // IoError on every rank if any failed
  std::vector<SnapshotInfo> drop_and_read(double last_time);  // resume: the file's part
  std::optional<SnapshotInfo> read_record(const std::string& name, double last_time) const;
  void reconcile_polyvertex(const std::vector<SnapshotInfo>& kept);
  void reconcile_walls(std::vector<SnapshotInfo>& kept);
  void reconcile_outlines(std::vector<SnapshotInfo>& kept);
  void reconcile_polygons(const std::vector<SnapshotInfo>& kept);
  void read_outlines(SnapshotInfo& record) const;

  MPI_Comm comm_;
  int rank_ = 0;
  std::string h5_path_;
  std::unique_ptr<XdmfSidecar> xdmf_;  // snapshots.xmf, kept by rank 0 (xdmf.hpp)
  std::optional<h5::ParallelFile> file_;
  std::vector<std::string> material_names_;  // /materials/name: snapshots.xmf names them
  std::optional<SnapshotInfo> last_;         // the last snapshot under /snapshots
  std::size_t written_ = 0;                  // snapshots under /snapshots
  std::map<std::string, Stored> stored_;     // by field name, or "walls/points", ...
  std::map<std::string, Stored> pending_;    // this write's new ones: stored_ once published
  std::chrono::steady_clock::time_point last_sync_ = std::chrono::steady_clock::now();
  bool closed_ = false;                       // close() was called
  std::uint64_t next_index_ = 0;              // NNNNNN of the next snapshot
  std::set<std::uint64_t> polyvertex_sizes_;  // n of every /xdmf/polyvertex_n written
  std::set<std::pair<std::uint64_t, std::uint64_t>> polygon_sizes_;  // (k, n): polygon_k_n
  bool shell_mesh_written_ = false;  // /shell_mesh is in the file, used by a published snapshot
  bool failed_ = false;              // the last write failed: clear its remains first
  std::optional<std::size_t> fail_before_dataset_;  // fail_before_dataset_for_testing
};

}  // namespace dem2d
