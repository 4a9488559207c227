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
//       (core/particles.hpp: id, material, position, velocity, angle, spin, radius), named as
//       the field, N rows (N x 2 for a Vec2), with string attributes `unit` and `doc` from the
//       field's FieldMeta; then any extra fields
//   /xdmf/polyvertex_N                   int64 0..N-1, the connectivity snapshots.xmf uses for
//                                        its Polyvertex topology (one per particle count N)
// N is the global number of owned particles; rank 0's particles come first, then rank 1's...
//
// snapshots.xmf (XDMF 3): a temporal collection with one Polyvertex grid per snapshot, XY
// geometry from position, and every other dataset as a point attribute (a Vec2 field, e.g.
// velocity, as a 2-component Vector). Checked with ParaView 5.11's "XDMF Reader" and
// "Xdmf3 Reader S/T".
//
// Every member is collective over the communicator. A failure throws IoError with the same
// message on every rank.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <vector>

#include "core/particles.hpp"
#include "core/scene.hpp"
#include "io/hdf5.hpp"
#include "parallel/comm.hpp"

namespace dem2d {

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
// in registry order. Throws std::logic_error for a marked field of a type it cannot write.
std::vector<SnapshotDataset> snapshot_datasets(const ParticleStore& particles);

class SnapshotWriter {
 public:
  // Creates (truncating) DIR/snapshots.h5 with the /materials table, and removes a stale
  // DIR/snapshots.xmf. Throws IoError "cannot create DIR/snapshots.h5: REASON" on every rank
  // when it cannot.
  SnapshotWriter(MPI_Comm comm, const std::string& directory,
                 const std::vector<MaterialSpec>& materials);
  ~SnapshotWriter();  // closes the file; never throws
  SnapshotWriter(const SnapshotWriter&) = delete;
  SnapshotWriter& operator=(const SnapshotWriter&) = delete;

  // Writes the owned particles [0, n_owned()) as the next /snapshots/NNNNNN group, flushes
  // the file, then rank 0 rewrites snapshots.xmf (atomically, via a rename).
  void write(const ParticleStore& particles, double time, std::int64_t step,
             std::span<const ExtraField> extra = {});

  // Closes the file and reports a failure (the destructor cannot). Later writes are errors.
  void close();

  const std::string& h5_path() const { return h5_path_; }
  const std::string& xdmf_path() const { return xdmf_path_; }
  std::size_t snapshots_written() const { return records_.size(); }

 private:
  struct Record {
    std::string name;  // NNNNNN
    double time = 0.0;
    std::int64_t step = 0;
    std::uint64_t particles = 0;
    std::vector<SnapshotDataset> datasets;  // registry fields, then extra fields
  };
  void write_materials(const std::vector<MaterialSpec>& materials);
  void write_datasets(const std::string& group, const h5::RowRange& rows, const ParticleStore& p,
                      std::span<const ExtraField> extra);
  std::string write_xdmf() const;  // rank 0; returns an error message, empty on success

  MPI_Comm comm_;
  int rank_ = 0;
  std::string h5_path_;
  std::string xdmf_path_;
  std::optional<h5::ParallelFile> file_;
  std::vector<Record> records_;
  std::set<std::uint64_t> polyvertex_sizes_;  // n of every /xdmf/polyvertex_n written
};

}  // namespace dem2d
