// SnapshotWriter: the HDF5 side of the snapshots (snapshots.hpp), its transactions on
// snapshots.h5; the sidecar snapshots.xmf is xdmf.cpp's, told here which snapshots there are.
#include "io/snapshots.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "core/base/errors.hpp"
#include "core/shape/outline.hpp"
#include "io/output_dir.hpp"
#include "io/snapshot_layout.hpp"
#include "io/xdmf.hpp"

namespace dem2d {
namespace {

namespace fs = std::filesystem;
using snapshot_layout::kGeometry;
using snapshot_layout::kMaterial;
using snapshot_layout::kOutlinesGroup;
using snapshot_layout::kOutlineVertices;
using snapshot_layout::kShellElementBar;
using snapshot_layout::kShellElements;
using snapshot_layout::kShellGroup;
using snapshot_layout::kShellMeshGroup;
using snapshot_layout::kShellQuadrilateralBar;
using snapshot_layout::kShellQuadrilaterals;
using snapshot_layout::kSnapshotsGroup;
using snapshot_layout::kWallsGroup;
using snapshot_layout::kXdmfGroup;
using snapshot_layout::material_lookup;
using snapshot_layout::polygon_dataset;
using snapshot_layout::polyvertex_dataset;

// The derived dataset every snapshot holds after the registry's: |velocity|.
const SnapshotDataset kSpeed{"speed", "double", 1, "m/s",
                             "speed of the centre, the norm of velocity"};

// A write syncs the files to disk (fsync) when this long has passed since the last sync.
constexpr std::chrono::seconds kSyncInterval{10};

// The group of the snapshot being written (snapshots.h5's other groups: snapshot_layout.hpp).
const std::string kStagingGroup = "/incomplete";

// Where snapshot NAME's wall outline is staged (beside its particles, /incomplete/NAME).
std::string staged_walls(const std::string& name) { return kStagingGroup + "/walls_" + name; }
// Where snapshot NAME's particle outlines are staged.
std::string staged_outlines(const std::string& name) { return kStagingGroup + "/outlines_" + name; }
// Where snapshot NAME's shell is staged.
std::string staged_shell(const std::string& name) { return kStagingGroup + "/shell_" + name; }

// The n of a member "polyvertex_n" of /xdmf; std::nullopt for another name.
std::optional<std::uint64_t> polyvertex_size(const std::string& member) {
  const std::string prefix = "polyvertex_";
  if (!member.starts_with(prefix) || member.size() == prefix.size()) return std::nullopt;
  const std::string digits = member.substr(prefix.size());
  if (digits.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  return std::stoull(digits);
}

// The (k, n) of a member "polygon_k_n" of /xdmf; std::nullopt for another name.
std::optional<std::pair<std::uint64_t, std::uint64_t>> polygon_size(const std::string& member) {
  const std::string prefix = "polygon_";
  if (!member.starts_with(prefix)) return std::nullopt;
  const std::string rest = member.substr(prefix.size());
  const std::size_t split = rest.find('_');
  if (split == 0 || split == std::string::npos || split + 1 == rest.size() ||
      rest.find_first_not_of("0123456789_") != std::string::npos ||
      rest.find('_', split + 1) != std::string::npos)
    return std::nullopt;
  return std::pair{std::stoull(rest.substr(0, split)), std::stoull(rest.substr(split + 1))};
}

// The number of a snapshot group's name (NNNNNN); std::nullopt for any other name.
std::optional<std::uint64_t> snapshot_index(const std::string& name) {
  if (name.empty() || name.size() > 18 || name.find_first_not_of("0123456789") != std::string::npos)
    return std::nullopt;
  return std::stoull(name);
}

}  // namespace

std::vector<SnapshotDataset> snapshot_datasets(const ParticleStore& particles) {
  std::vector<SnapshotDataset> out;
  for (const FieldBase* f : particles.fields()) {
    if (!f->meta().snapshot) continue;
    const std::optional<h5::FieldColumn> c = h5::field_column(*f);
    if (!c)
      throw std::logic_error("SnapshotWriter: field '" + f->name() +
                             "' is marked for snapshots but its type cannot be written");
    out.push_back(
        {f->name(), h5::element_name(c->element), c->columns, f->meta().unit, f->meta().doc});
  }
  out.push_back(kSpeed);
  return out;
}

SnapshotWriter::SnapshotWriter(NoFile, MPI_Comm comm, const std::string& directory)
    : comm_(comm),
      rank_(mpi::rank(comm)),
      h5_path_((fs::path(directory) / kSnapshotsFile).string()),
      xdmf_(std::make_unique<XdmfSidecar>((fs::path(directory) / kXdmfFile).string(),
                                          fs::path(h5_path_).filename().string())) {}

SnapshotWriter::SnapshotWriter(MPI_Comm comm, const std::string& directory,
                               const std::vector<MaterialSpec>& materials)
    : SnapshotWriter(NoFile{}, comm, directory) {
  // Rank 0 tries the path first with plain stdio: the usual failures (no such directory, not
  // writable) give a clear reason, and all ranks learn of them before the collective create.
  std::string error;
  if (rank_ == 0) {
    std::FILE* probe = std::fopen(h5_path_.c_str(), "wb");
    if (probe == nullptr) {
      error = fmt::format("cannot create {}: {}", h5_path_, std::strerror(errno));
    } else {
      std::fclose(probe);
      std::error_code ec;
      fs::remove(xdmf_->path(), ec);  // a stale sidecar would point at groups no longer there
    }
  }
  mpi::agree_on_failure<IoError>(comm_, error);
  try {
    file_.emplace(h5::ParallelFile::create(comm_, h5_path_));
    write_materials(materials);
    file_->create_group(kSnapshotsGroup);
    file_->create_group(kWallsGroup);
    file_->create_group(kStagingGroup);
    file_->create_group(kXdmfGroup);
    file_->close();  // reopened by each write
  } catch (const IoError& e) {
    error = e.what();
  }
  file_.reset();
  mpi::agree_on_failure<IoError>(comm_, error);
}

std::unique_ptr<SnapshotWriter> SnapshotWriter::resume(MPI_Comm comm, const std::string& directory,
                                                       const std::vector<MaterialSpec>& materials,
                                                       double time, double tolerance) {
  const std::string path = (fs::path(directory) / kSnapshotsFile).string();
  std::string found;
  if (mpi::rank(comm) == 0) {
    std::error_code ec;
    if (fs::exists(path, ec)) found = "yes";
  }
  if (mpi::broadcast_string(comm, found, 0).empty())
    return std::make_unique<SnapshotWriter>(comm, directory, materials);
  std::unique_ptr<SnapshotWriter> w(new SnapshotWriter(NoFile{}, comm, directory));
  std::vector<SnapshotInfo> kept;
  std::string error;
  try {
    w->file_.emplace(h5::ParallelFile::open(comm, path));
    kept = w->drop_and_read(time + tolerance);
    w->file_->flush();  // the file as the restart left it, on disk
    w->file_->close();
  } catch (const IoError& e) {
    error = e.what();
  }
  w->agree(error);
  w->file_.reset();
  if (w->rank_ == 0) error = w->xdmf_->rewrite(kept, w->material_names_);
  w->agree(error);
  w->written_ = kept.size();
  if (!kept.empty()) w->last_ = std::move(kept.back());
  return w;
}

// Closes the file through the handle's destructor, which ignores (cannot report) a failure.
SnapshotWriter::~SnapshotWriter() = default;

const std::string& SnapshotWriter::xdmf_path() const { return xdmf_->path(); }

void SnapshotWriter::write_materials(const std::vector<MaterialSpec>& materials) {
  file_->create_group("/materials");
  const h5::RowRange rows = h5::rank0_rows(comm_, materials.size());
  material_names_.clear();
  for (const auto& m : materials) material_names_.push_back(m.name);
  file_->write_strings("/materials/name", material_names_);
  auto column = [&](const char* name, double MaterialSpec::*member) {
    std::vector<double> values;
    for (const auto& m : materials) values.push_back(m.*member);
    file_->write_rows(std::string("/materials/") + name, rows, values.data());
  };
  column("density", &MaterialSpec::density);
  column("youngs_modulus", &MaterialSpec::youngs_modulus);
  column("poisson_ratio", &MaterialSpec::poisson_ratio);
  column("shear_modulus", &MaterialSpec::shear_modulus);
  column("restitution", &MaterialSpec::restitution);
  column("damping_normal", &MaterialSpec::damping_normal);
  column("damping_tangential", &MaterialSpec::damping_tangential);
  column("sliding_friction", &MaterialSpec::sliding_friction);
  column("rolling_friction", &MaterialSpec::rolling_friction);
  column("normal_stiffness", &MaterialSpec::normal_stiffness);
}

SnapshotInfo SnapshotWriter::describe(const ParticleStore& p, double time, std::int64_t step,
                                      std::span<const ExtraField> extra) const {
  SnapshotInfo record{fmt::format("{:06d}", next_index_), time, step, 0, snapshot_datasets(p)};
  for (const ExtraField& e : extra) {
    const bool taken = std::any_of(record.datasets.begin(), record.datasets.end(),
                                   [&](const SnapshotDataset& d) { return d.name == e.name; });
    if (e.values.size() != p.n_owned() || taken || e.name.empty())
      throw std::invalid_argument("SnapshotWriter: bad extra field '" + e.name + "'");
    record.datasets.push_back({e.name, "double", 1, e.unit, e.doc});
  }
  return record;
}

// A wall outline as snapshots.h5 holds it: the points of the polylines, and each polyline's
// segments as pairs of point rows. A closed polyline (its last point its first) reuses its
// first point; a polyline of fewer than 2 points is left out.
struct SnapshotWriter::WallData {
  std::vector<double> points;          // x0, y0, x1, y1, ...
  std::vector<std::int64_t> segments;  // a0, b0, a1, b1, ...
};

SnapshotWriter::WallData SnapshotWriter::wall_data(std::span<const std::vector<Vec2>> outlines) {
  WallData w;
  for (const std::vector<Vec2>& line : outlines) {
    if (line.size() < 2) continue;
    const auto first = static_cast<std::int64_t>(w.points.size() / 2);
    const bool closed = line.size() > 2 && line.back() == line.front();
    const std::size_t own = closed ? line.size() - 1 : line.size();  // points it adds
    for (std::size_t k = 0; k < own; ++k) {
      w.points.push_back(line[k].x);
      w.points.push_back(line[k].y);
    }
    for (std::size_t k = 0; k + 1 < line.size(); ++k) {
      w.segments.push_back(first + static_cast<std::int64_t>(k));
      w.segments.push_back(first + static_cast<std::int64_t>((k + 1) % own));
    }
  }
  return w;
}

// rank 0's outline rows and whether this write syncs the file to disk (rank 0's clock), for
// every rank: `header` is {points, segments, sync, shell nodes, shell elements, shell
// fields not matching the mesh}.
void SnapshotWriter::sync_due(std::array<int, 6>& header) {
  const auto now = std::chrono::steady_clock::now();
  header[2] = now - last_sync_ >= kSyncInterval ? 1 : 0;
  mpi::broadcast(comm_, header, 0);
  if (header[2] != 0) last_sync_ = now;
}

void SnapshotWriter::write(const ParticleStore& p, double time, std::int64_t step,
                           std::span<const std::vector<Vec2>> walls,
                           std::span<const ExtraField> extra, const ShellSnapshot* shell) {
  if (closed_) throw std::logic_error("SnapshotWriter::write after close");
  SnapshotInfo record = describe(p, time, step, extra);
  const WallData outline = wall_data(walls);
  const bool has_shell = shell != nullptr && !shell->position.empty() && !shell->elements.empty();
  const bool bad_shell = has_shell && (shell->displacement.size() != shell->position.size() ||
                                       shell->von_mises.size() != shell->position.size() ||
                                       shell->element_bar.size() != shell->elements.size());
  std::array<int, 6> header{static_cast<int>(outline.points.size() / 2),
                            static_cast<int>(outline.segments.size() / 2),
                            0,
                            has_shell ? static_cast<int>(shell->position.size()) : 0,
                            has_shell ? static_cast<int>(shell->elements.size()) : 0,
                            bad_shell ? 1 : 0};
  sync_due(header);  // rank 0's outline and shell are written
  if (header[5] != 0)
    throw std::invalid_argument("SnapshotWriter: the shell's fields do not match its mesh");
  record.wall_points = static_cast<std::uint64_t>(header[0]);
  record.wall_segments = static_cast<std::uint64_t>(header[1]);
  record.shell_nodes = static_cast<std::uint64_t>(header[3]);
  record.shell_elements = static_cast<std::uint64_t>(header[4]);
  std::uint64_t row_bytes = 0;
  for (const SnapshotDataset& d : record.datasets)
    row_bytes += d.columns * (d.type == "int32" ? 4 : 8);
  const std::uint64_t total = h5::row_range(comm_, p.n_owned()).total;
  if (p.shaped() && total > 0) {
    record.outline_vertices = kOutlineVertices;
    row_bytes += 8 * kOutlineVertices;  // the outline's points (float x, y)
    if (!polygon_sizes_.contains({kOutlineVertices, total})) row_bytes += 8 * kOutlineVertices;
  }
  const std::uint64_t shell_bytes =
      40 * record.shell_nodes + (shell_mesh_written_ ? 0 : 240 * record.shell_elements);
  ensure_free_space(comm_, h5_path_,
                    total * row_bytes + 16 * (record.wall_points + record.wall_segments) +
                        shell_bytes + 2048 * (record.datasets.size() + 2) + 16384);
  std::string error;
  try {
    if (!file_) file_.emplace(h5::ParallelFile::open(comm_, h5_path_));
    if (failed_) clear_failed_write(record.name);
    const h5::RowRange rows = h5::row_range(comm_, p.n_owned());
    record.particles = rows.total;
    stage(kStagingGroup + "/" + record.name, record, rows, p, extra, outline, shell);
  } catch (const IoError& e) {
    error = e.what();
  }
  agree(error);
  const bool sync = header[2] != 0;
  std::optional<std::vector<SnapshotInfo>> whole = publish(record, sync);
  if (record.particles > 0) polyvertex_sizes_.insert(record.particles);
  if (record.outline_vertices > 0)
    polygon_sizes_.insert({record.outline_vertices, record.particles});
  if (record.shell_nodes > 0) shell_mesh_written_ = true;
  last_ = record;
  ++written_;
  ++next_index_;
  if (rank_ == 0) {  // the sidecar lists the snapshot only now that the closed file holds it
    error =
        whole ? xdmf_->rewrite(*whole, material_names_) : xdmf_->append(record, material_names_);
    if (error.empty() && sync) error = xdmf_->sync();
  }
  agree(error);
}

// Moves the staged snapshot and its outline to /snapshots and /walls and closes the file (its
// metadata written out; synced to disk only when `sync`). Returns, on rank 0 when snapshots.xmf
// must be written whole, every snapshot the file now holds.
std::optional<std::vector<SnapshotInfo>> SnapshotWriter::publish(const SnapshotInfo& record,
                                                                 bool sync) {
  std::optional<std::vector<SnapshotInfo>> whole;
  std::string error;
  try {
    if (record.wall_segments > 0)  // the outline first: a published snapshot has its outline
      file_->move_link(staged_walls(record.name), kWallsGroup + "/" + record.name);
    if (record.outline_vertices > 0)  // likewise its particles' outlines
      file_->move_link(staged_outlines(record.name), kOutlinesGroup + "/" + record.name);
    if (record.shell_nodes > 0)  // and its shell
      file_->move_link(staged_shell(record.name), kShellGroup + "/" + record.name);
    file_->move_link(kStagingGroup + "/" + record.name, kSnapshotsGroup + "/" + record.name);
    for (auto& [key, stored] : pending_) stored_[key] = std::move(stored);
    pending_.clear();
    if (sync) file_->flush();  // H5Fflush: MPI_File_sync, an fsync
    if (rank_ == 0 && !xdmf_->can_append()) whole = published_records();
    file_->close();  // every snapshot's metadata in the file: a reader (or a kill) sees it whole
    file_.reset();
    H5garbage_collect();  // HDF5's free lists, grown by this file's metadata, back to the heap
  } catch (const IoError& e) {
    error = e.what();
  }
  agree(error);
  return whole;
}

void SnapshotWriter::agree(const std::string& local_error) {
  std::string message = mpi::first_failure(comm_, local_error);
  if (message.empty()) return;
  failed_ = true;
  pending_.clear();
  file_.reset();  // on every rank (a collective close, errors ignored): the next write reopens it
  throw IoError(message);
}

// Before the write after a failed one: removes what the failed write of snapshot `name` left
// (its staging groups; its published groups if it failed after a move, before it was
// recorded; a connectivity dataset no recorded snapshot uses), so the write can start afresh.
void SnapshotWriter::clear_failed_write(const std::string& name) {
  const bool outlines = file_->link_exists(kOutlinesGroup);
  const bool shells = file_->link_exists(kShellGroup);
  for (const std::string& g :
       {kStagingGroup + "/" + name, staged_walls(name), staged_outlines(name), staged_shell(name),
        kSnapshotsGroup + "/" + name, kWallsGroup + "/" + name, kOutlinesGroup + "/" + name,
        kShellGroup + "/" + name}) {
    if (g.starts_with(kOutlinesGroup + "/") && !outlines) continue;
    if (g.starts_with(kShellGroup + "/") && !shells) continue;
    if (file_->link_exists(g)) file_->remove_link(g);
    std::erase_if(stored_, [&](const auto& s) { return s.second.path.starts_with(g + "/"); });
  }
  for (const std::string& member : file_->group_members(kXdmfGroup)) {
    const std::optional<std::uint64_t> n = polyvertex_size(member);
    const auto polygon = polygon_size(member);
    if ((n && !polyvertex_sizes_.contains(*n)) || (polygon && !polygon_sizes_.contains(*polygon)))
      file_->remove_link(kXdmfGroup + "/" + member);
  }
  if (!shell_mesh_written_ && file_->link_exists(kShellMeshGroup))
    file_->remove_link(kShellMeshGroup);  // no published snapshot uses it
  failed_ = false;
}

// The snapshot as the staging group `group`, with the connectivity it needs and its wall
// outline (staged_walls).
void SnapshotWriter::stage(const std::string& group, const SnapshotInfo& record,
                           const h5::RowRange& rows, const ParticleStore& p,
                           std::span<const ExtraField> extra, const WallData& walls,
                           const ShellSnapshot* shell) {
  file_->create_group(group, /*track_order=*/true);  // resume() reads the datasets in order
  file_->write_attribute(group, "time", record.time);
  file_->write_attribute(group, "step", record.step);
  write_datasets(group, kSnapshotsGroup + "/" + record.name, rows, p, extra);
  if (rows.total > 0 && !polyvertex_sizes_.contains(rows.total)) write_polyvertex(rows);
  if (record.wall_segments > 0) write_walls(staged_walls(record.name), record, walls);
  if (record.outline_vertices > 0) {
    write_outlines(staged_outlines(record.name), record, rows, p);
    if (!polygon_sizes_.contains({record.outline_vertices, rows.total}))
      write_polygons(record.outline_vertices, rows);
  }
  if (record.shell_nodes > 0) write_shell(staged_shell(record.name), record, shell);
  if (fail_before_dataset_) {  // testing: past the last dataset, fail before the flush
    fail_before_dataset_.reset();
    throw IoError(fmt::format("{}: cannot close '{}': injected failure", h5_path_, group));
  }
}

// Whether the dataset `key` (this write's rows `data`, `bytes` long on this rank) is unchanged
// since it was last stored, on every rank: then `staged` becomes a second name (a hard link) of
// the stored dataset and true is returned. Otherwise the caller writes it at `staged`, and it is
// the one stored under `published` once this snapshot is published.
bool SnapshotWriter::link_if_unchanged(const std::string& key, const std::string& staged,
                                       const std::string& published, const h5::RowRange& rows,
                                       const void* data, std::size_t bytes) {
  const auto it = stored_.find(key);
  const bool same = it != stored_.end() && it->second.rows.offset == rows.offset &&
                    it->second.rows.count == rows.count && it->second.rows.total == rows.total &&
                    it->second.bytes.size() == bytes &&
                    (bytes == 0 || std::memcmp(it->second.bytes.data(), data, bytes) == 0);
  if (!mpi::any(comm_, !same)) {
    file_->hard_link(it->second.path, staged);
    return true;
  }
  const auto* first = static_cast<const std::byte*>(data);
  pending_[key] = Stored{published, rows, std::vector<std::byte>(first, first + bytes)};
  return false;
}

namespace {

// The bytes of this rank's rows of a particle field as a dataset holds them.
std::size_t field_bytes(const h5::FieldColumn& c, const h5::RowRange& rows) {
  return rows.count * c.columns * (c.element == h5::FieldColumn::kInt32 ? 4 : 8);
}

}  // namespace

// The registry's snapshot fields in registry order, then speed, then the extra fields; each
// dataset with its unit and description as attributes, so a file explains itself, and the
// material rows with the material names (attribute `names`, "0=steel,1=ore"). A stable field
// whose rows are those last stored is linked to them (link_if_unchanged), not written again.
void SnapshotWriter::write_datasets(const std::string& group, const std::string& published,
                                    const h5::RowRange& rows, const ParticleStore& p,
                                    std::span<const ExtraField> extra) {
  std::size_t written = 0;
  const auto begin = [&](const std::string& name) {  // fail_before_dataset_for_testing
    if (fail_before_dataset_ && *fail_before_dataset_ == written++) {
      fail_before_dataset_.reset();
      throw IoError(fmt::format("{}: cannot write dataset '{}': injected failure", h5_path_, name));
    }
  };
  const auto describe = [&](const std::string& name, const std::string& unit,
                            const std::string& doc) {
    file_->write_attribute(name, "unit", unit);
    file_->write_attribute(name, "doc", doc);
  };
  for (const FieldBase* f : p.fields()) {
    if (!f->meta().snapshot) continue;
    const std::string name = group + "/" + f->name();
    begin(name);
    const h5::FieldColumn c = *h5::field_column(*f);  // snapshot_datasets checked the type
    if (f->meta().stable && link_if_unchanged(f->name(), name, published + "/" + f->name(), rows,
                                              c.data, field_bytes(c, rows)))
      continue;
    file_->write_field(name, rows, *f);
    describe(name, f->meta().unit, f->meta().doc);
    if (f->name() == kMaterial)
      file_->write_attribute(name, "names", material_lookup(material_names_));
  }
  const std::string speed_name = group + "/" + kSpeed.name;
  begin(speed_name);
  std::vector<double> speed(rows.count);
  for (std::size_t i = 0; i < speed.size(); ++i) speed[i] = norm(p.vel[i]);
  file_->write_rows(speed_name, rows, speed.data());
  describe(speed_name, kSpeed.unit, kSpeed.doc);
  for (const ExtraField& e : extra) {
    const std::string name = group + "/" + e.name;
    begin(name);
    file_->write_rows(name, rows, e.values.data());
    describe(name, e.unit, e.doc);
  }
}

// The wall outline of snapshot `record` as the group `group`: its time and step, the points
// (M x 2) and the segments (S x 2 point rows); rank 0's, the same on every rank. Points or
// segments equal to those last stored are linked to them (link_if_unchanged): the segments of
// a scene are written once, its points again only when the walls have moved.
void SnapshotWriter::write_walls(const std::string& group, const SnapshotInfo& record,
                                 const WallData& walls) {
  file_->create_group(group);
  file_->write_attribute(group, "time", record.time);
  file_->write_attribute(group, "step", record.step);
  const std::string published = kWallsGroup + "/" + record.name;
  const h5::RowRange point_rows = h5::rank0_rows(comm_, record.wall_points);
  const std::string points = group + "/points";
  if (!link_if_unchanged("walls/points", points, published + "/points", point_rows,
                         walls.points.data(), point_rows.count * 16)) {
    file_->write_rows(points, point_rows, walls.points.data(), 2);
    file_->write_attribute(points, "unit", std::string("m"));
    file_->write_attribute(points, "doc",
                           std::string("x and y of the outline's points, lab frame"));
  }
  const h5::RowRange segment_rows = h5::rank0_rows(comm_, record.wall_segments);
  const std::string segments = group + "/segments";
  if (!link_if_unchanged("walls/segments", segments, published + "/segments", segment_rows,
                         walls.segments.data(), segment_rows.count * 16)) {
    file_->write_rows(segments, segment_rows, walls.segments.data(), 2);
    file_->write_attribute(segments, "unit", std::string("1"));
    file_->write_attribute(segments, "doc",
                           std::string("rows of `points` joined by each straight piece"));
  }
}

// The shell's state at snapshot `record` as the group `group`: its time and step, and per node
// (rows of FeMesh::nodes) the position, displacement and von Mises stress; rank 0's. With the
// file's first such snapshot, the mesh too (write_shell_mesh).
void SnapshotWriter::write_shell(const std::string& group, const SnapshotInfo& record,
                                 const ShellSnapshot* shell) {
  const ShellSnapshot none{};
  const ShellSnapshot& s = rank_ == 0 && shell != nullptr ? *shell : none;
  if (!file_->link_exists(kShellGroup)) file_->create_group(kShellGroup);
  file_->create_group(group);
  file_->write_attribute(group, "time", record.time);
  file_->write_attribute(group, "step", record.step);
  const h5::RowRange rows = h5::rank0_rows(comm_, record.shell_nodes);
  const auto xy = [&](std::span<const Vec2> v) {
    std::vector<double> out(2 * rows.count);
    for (std::size_t k = 0; k < rows.count; ++k) {
      out[2 * k] = v[k].x;
      out[2 * k + 1] = v[k].y;
    }
    return out;
  };
  const auto describe = [&](const std::string& name, const char* unit, const char* doc) {
    file_->write_attribute(name, "unit", std::string(unit));
    file_->write_attribute(name, "doc", std::string(doc));
  };
  file_->write_rows(group + "/points", rows, xy(s.position).data(), 2);
  describe(group + "/points", "m",
           "x and y of the mesh's nodes at rest, lab frame (the drum frame's mesh turned by the "
           "drum's angle about its centre)");
  file_->write_rows(group + "/displacement", rows, xy(s.displacement).data(), 2);
  describe(group + "/displacement", "m",
           "the nodes' displacement under the snapshot's wall loads, lab frame");
  std::vector<double> von_mises(s.von_mises.begin(),
                                s.von_mises.begin() + static_cast<std::ptrdiff_t>(rows.count));
  file_->write_rows(group + "/von_mises", rows, von_mises.data());
  describe(group + "/von_mises", "Pa",
           "von Mises stress at the nodes, the elements' values extrapolated from their Gauss "
           "points and averaged over the elements sharing the node");
  if (!shell_mesh_written_ && !file_->link_exists(kShellMeshGroup)) write_shell_mesh(record, shell);
}

// /shell_mesh: the elements (E x 9 rows of /shell/NNNNNN/points, the 9-node order of
// core/structure/fe_mesh.hpp), each element's bar, and each element split into four 4-node
// quadrilaterals over its nodes, rows 4 e .. 4 e + 3 for element e (with their bars); rank 0's.
void SnapshotWriter::write_shell_mesh(const SnapshotInfo& record, const ShellSnapshot* shell) {
  const ShellSnapshot none{};
  const ShellSnapshot& s = rank_ == 0 && shell != nullptr ? *shell : none;
  // The quadrilaterals of a 9-node element, counter-clockwise like it: corner, mid-side, centre,
  // mid-side, one per corner.
  static constexpr std::array<std::array<int, 4>, 4> kQuarters{
      {{0, 4, 8, 7}, {4, 1, 5, 8}, {8, 5, 2, 6}, {7, 8, 6, 3}}};
  const h5::RowRange rows = h5::rank0_rows(comm_, record.shell_elements);
  const h5::RowRange quad_rows = h5::rank0_rows(comm_, 4 * record.shell_elements);
  std::vector<std::int64_t> elements, bars, quads, quad_bars;
  for (std::size_t e = 0; e < rows.count; ++e) {
    for (const int node : s.elements[e]) elements.push_back(node);
    bars.push_back(s.element_bar[e]);
    for (const std::array<int, 4>& q : kQuarters) {
      for (const int corner : q) quads.push_back(s.elements[e][static_cast<std::size_t>(corner)]);
      quad_bars.push_back(s.element_bar[e]);
    }
  }
  file_->create_group(kShellMeshGroup);
  const auto describe = [&](const std::string& name, const char* doc) {
    file_->write_attribute(name, "unit", std::string("1"));
    file_->write_attribute(name, "doc", std::string(doc));
  };
  file_->write_rows(kShellElements, rows, elements.data(), 9);
  describe(kShellElements,
           "the 9-node elements as rows of the shell's points: corners, mid-sides, centre, "
           "counter-clockwise");
  file_->write_rows(kShellElementBar, rows, bars.data());
  describe(kShellElementBar, "each element's lifter bar (0, 1, ...), -1 for the shell ring");
  file_->write_rows(kShellQuadrilaterals, quad_rows, quads.data(), 4);
  describe(kShellQuadrilaterals,
           "each element split into four 4-node quadrilaterals over its 9 nodes, rows 4 e to "
           "4 e + 3 for element e");
  file_->write_rows(kShellQuadrilateralBar, quad_rows, quad_bars.data());
  describe(kShellQuadrilateralBar, "each quadrilateral's lifter bar, -1 for the shell ring");
}

// /xdmf/polyvertex_N for N = rows.total: 0, 1, ..., N - 1, each rank writing its rows.
void SnapshotWriter::write_polyvertex(const h5::RowRange& rows) {
  std::vector<std::int64_t> index(rows.count);
  for (std::uint64_t i = 0; i < rows.count; ++i)
    index[i] = static_cast<std::int64_t>(rows.offset + i);
  file_->write_rows(polyvertex_dataset(rows.total), rows, index.data());
}

// The outlines of the owned particles as the group `group` (core/shape/outline.hpp): the
// points, record.outline_vertices rows per particle in the snapshot's row order, as floats
// (the drawing needs no more; half the bytes).
void SnapshotWriter::write_outlines(const std::string& group, const SnapshotInfo& record,
                                    const h5::RowRange& rows, const ParticleStore& p) {
  const std::uint64_t k = record.outline_vertices;
  std::vector<Vec2> polygon(k);
  std::vector<float> points(2 * k * rows.count);
  for (std::size_t i = 0; i < rows.count; ++i) {
    superellipse_outline({(*p.semi_a())[i], (*p.semi_b())[i], (*p.exponent())[i]}, p.pos[i],
                         p.theta[i], polygon);
    for (std::uint64_t j = 0; j < k; ++j) {
      points[2 * (i * k + j)] = static_cast<float>(polygon[j].x);
      points[2 * (i * k + j) + 1] = static_cast<float>(polygon[j].y);
    }
  }
  if (!file_->link_exists(kOutlinesGroup)) file_->create_group(kOutlinesGroup);
  file_->create_group(group);
  file_->write_attribute(group, "time", record.time);
  file_->write_attribute(group, "step", record.step);
  const std::string name = group + "/points";
  file_->write_rows(name, {rows.offset * k, rows.count * k, rows.total * k}, points.data(), 2);
  file_->write_attribute(name, "unit", std::string("m"));
  file_->write_attribute(
      name, "doc",
      fmt::format("x and y of each particle's outline, {} points per particle in the "
                  "snapshot's row order, counter-clockwise, lab frame",
                  k));
}

// /xdmf/polygon_K_N for N = rows.total: row i is i K, ..., i K + K - 1, each rank its rows.
void SnapshotWriter::write_polygons(std::uint64_t vertices, const h5::RowRange& rows) {
  std::vector<std::int64_t> index(rows.count * vertices);
  for (std::uint64_t i = 0; i < index.size(); ++i)
    index[i] = static_cast<std::int64_t>(rows.offset * vertices + i);
  file_->write_rows(polygon_dataset(vertices, rows.total), rows, index.data(), vertices);
}

// resume(): empties /incomplete, drops the snapshots after `last_time`, records the others in
// order and makes /xdmf hold exactly the connectivity they use.
std::vector<SnapshotInfo> SnapshotWriter::drop_and_read(double last_time) {
  if (!file_->link_exists(kSnapshotsGroup))
    throw IoError(fmt::format("{}: cannot resume: no {} group", h5_path_, kSnapshotsGroup));
  material_names_ = file_->read_strings("/materials/name");
  if (file_->link_exists(kStagingGroup)) {
    for (const std::string& m : file_->group_members(kStagingGroup))
      file_->remove_link(kStagingGroup + "/" + m);
  } else {
    file_->create_group(kStagingGroup);
  }
  if (!file_->link_exists(kXdmfGroup)) file_->create_group(kXdmfGroup);
  if (!file_->link_exists(kWallsGroup)) file_->create_group(kWallsGroup);  // an older file
  std::vector<std::pair<std::uint64_t, std::string>> groups;
  for (const std::string& name : file_->group_members(kSnapshotsGroup)) {
    const std::optional<std::uint64_t> index = snapshot_index(name);
    if (!index)
      throw IoError(fmt::format("{}: cannot resume: '{}/{}' is not a snapshot", h5_path_,
                                kSnapshotsGroup, name));
    groups.emplace_back(*index, name);
  }
  std::sort(groups.begin(), groups.end());
  std::vector<SnapshotInfo> kept;
  for (const auto& [index, name] : groups) {
    std::optional<SnapshotInfo> record = read_record(name, last_time);
    if (!record) {
      file_->remove_link(kSnapshotsGroup + "/" + name);
      continue;
    }
    kept.push_back(std::move(*record));
    next_index_ = index + 1;
  }
  reconcile_polyvertex(kept);
  reconcile_walls(kept);
  reconcile_outlines(kept);
  reconcile_polygons(kept);
  reconcile_shell(kept);
  return kept;
}

// Every snapshot under /snapshots in order, with its outline: what snapshots.xmf lists when it
// is written whole. Rank 0 alone reads them (the writer keeps no list).
std::vector<SnapshotInfo> SnapshotWriter::published_records() const {
  std::vector<std::pair<std::uint64_t, std::string>> groups;
  for (const std::string& name : file_->group_members(kSnapshotsGroup))
    if (const std::optional<std::uint64_t> index = snapshot_index(name))
      groups.emplace_back(*index, name);
  std::sort(groups.begin(), groups.end());
  std::vector<SnapshotInfo> out;
  for (const auto& [index, name] : groups) {
    out.push_back(*read_record(name, std::numeric_limits<double>::infinity()));
    if (file_->link_exists(kWallsGroup + "/" + name)) read_walls(out.back());
    if (file_->link_exists(kOutlinesGroup) && file_->link_exists(kOutlinesGroup + "/" + name))
      read_outlines(out.back());
    if (file_->link_exists(kShellGroup) && file_->link_exists(kShellGroup + "/" + name))
      read_shell(out.back());
  }
  return out;
}

// The snapshot /snapshots/NAME as the file holds it; std::nullopt when its time is after
// `last_time`. Throws IoError for a group that is not a snapshot dem2d wrote.
std::optional<SnapshotInfo> SnapshotWriter::read_record(const std::string& name,
                                                        double last_time) const {
  const std::string group = kSnapshotsGroup + "/" + name;
  SnapshotInfo r{name, file_->read_double_attribute(group, "time"), 0, 0, {}};
  if (r.time > last_time) return std::nullopt;
  r.step = file_->read_int64_attribute(group, "step");
  std::optional<std::uint64_t> rows;
  for (const std::string& d : file_->group_members(group)) {
    const std::string path = group + "/" + d;
    const h5::ParallelFile::DatasetShape shape = file_->dataset_shape(path);
    if (rows && *rows != shape.rows)
      throw IoError(fmt::format("{}: cannot resume: '{}' has {} rows, not {}", h5_path_, path,
                                shape.rows, *rows));
    rows = shape.rows;
    r.datasets.push_back({d, shape.type, shape.columns, file_->read_string_attribute(path, "unit"),
                          file_->read_string_attribute(path, "doc")});
  }
  const bool has_geometry =
      std::any_of(r.datasets.begin(), r.datasets.end(),
                  [](const SnapshotDataset& d) { return d.name == kGeometry; });
  if (!has_geometry)
    throw IoError(
        fmt::format("{}: cannot resume: '{}' has no {} dataset", h5_path_, group, kGeometry));
  r.particles = *rows;
  return r;
}

// resume(): records the wall outline of every kept snapshot that has one and removes the
// others (those of dropped snapshots, or left by a write that failed between its moves).
void SnapshotWriter::reconcile_walls(std::vector<SnapshotInfo>& kept) {
  std::map<std::string, SnapshotInfo*> by_name;
  for (SnapshotInfo& r : kept) by_name[r.name] = &r;
  for (const std::string& member : file_->group_members(kWallsGroup)) {
    const auto it = by_name.find(member);
    if (it == by_name.end())
      file_->remove_link(kWallsGroup + "/" + member);
    else
      read_walls(*it->second);
  }
}

// The rows of /walls/NAME's points and segments into `record` (NAME its name). Throws IoError
// for a group that is not a wall outline.
void SnapshotWriter::read_walls(SnapshotInfo& record) const {
  const std::string group = kWallsGroup + "/" + record.name;
  const bool complete =
      file_->link_exists(group + "/points") && file_->link_exists(group + "/segments");
  const h5::ParallelFile::DatasetShape points =
      complete ? file_->dataset_shape(group + "/points") : h5::ParallelFile::DatasetShape{};
  const h5::ParallelFile::DatasetShape segments =
      complete ? file_->dataset_shape(group + "/segments") : h5::ParallelFile::DatasetShape{};
  if (!complete || points.type != "double" || points.columns != 2 || segments.type != "int64" ||
      segments.columns != 2 || segments.rows == 0)
    throw IoError(fmt::format("{}: cannot resume: '{}' is not a wall outline", h5_path_, group));
  record.wall_points = points.rows;
  record.wall_segments = segments.rows;
}

// resume(): records the particle outlines of every kept snapshot that has them and removes the
// others (those of dropped snapshots, or left by a write that failed between its moves).
void SnapshotWriter::reconcile_outlines(std::vector<SnapshotInfo>& kept) {
  if (!file_->link_exists(kOutlinesGroup)) return;  // no shaped particles
  std::map<std::string, SnapshotInfo*> by_name;
  for (SnapshotInfo& r : kept) by_name[r.name] = &r;
  for (const std::string& member : file_->group_members(kOutlinesGroup)) {
    const auto it = by_name.find(member);
    if (it == by_name.end())
      file_->remove_link(kOutlinesGroup + "/" + member);
    else
      read_outlines(*it->second);
  }
}

// The points per particle of /outlines/NAME into `record` (NAME its name). Throws IoError for
// a group that is not the outlines of the snapshot's particles.
void SnapshotWriter::read_outlines(SnapshotInfo& record) const {
  const std::string points = kOutlinesGroup + "/" + record.name + "/points";
  const h5::ParallelFile::DatasetShape shape =
      file_->link_exists(points) ? file_->dataset_shape(points) : h5::ParallelFile::DatasetShape{};
  const std::uint64_t k = record.particles == 0 ? 0 : shape.rows / record.particles;
  if (shape.type != "float" || shape.columns != 2 || k == 0 || k * record.particles != shape.rows)
    throw IoError(fmt::format("{}: cannot resume: '{}/{}' is not the outlines of its snapshot",
                              h5_path_, kOutlinesGroup, record.name));
  record.outline_vertices = k;
}

// resume(): records the shell of every kept snapshot that has one and removes the others (those
// of dropped snapshots, or left by a write that failed between its moves); removes /shell_mesh
// when no kept snapshot has a shell (the next one writes it again).
void SnapshotWriter::reconcile_shell(std::vector<SnapshotInfo>& kept) {
  if (file_->link_exists(kShellGroup)) {
    std::map<std::string, SnapshotInfo*> by_name;
    for (SnapshotInfo& r : kept) by_name[r.name] = &r;
    for (const std::string& member : file_->group_members(kShellGroup)) {
      const auto it = by_name.find(member);
      if (it == by_name.end())
        file_->remove_link(kShellGroup + "/" + member);
      else
        read_shell(*it->second);
    }
  }
  shell_mesh_written_ = std::any_of(kept.begin(), kept.end(),
                                    [](const SnapshotInfo& r) { return r.shell_nodes > 0; });
  if (!shell_mesh_written_ && file_->link_exists(kShellMeshGroup))
    file_->remove_link(kShellMeshGroup);
}

// The rows of /shell/NAME's datasets and of the mesh's elements into `record` (NAME its name).
// Throws IoError for a group that is not the shell of a snapshot.
void SnapshotWriter::read_shell(SnapshotInfo& record) const {
  const std::string group = kShellGroup + "/" + record.name;
  const auto shape = [&](const std::string& path) {
    return file_->link_exists(path) ? file_->dataset_shape(path) : h5::ParallelFile::DatasetShape{};
  };
  const h5::ParallelFile::DatasetShape points = shape(group + "/points");
  const h5::ParallelFile::DatasetShape displacement = shape(group + "/displacement");
  const h5::ParallelFile::DatasetShape von_mises = shape(group + "/von_mises");
  const h5::ParallelFile::DatasetShape elements = shape(kShellElements);
  const h5::ParallelFile::DatasetShape quads = shape(kShellQuadrilaterals);
  const bool ok = points.type == "double" && points.columns == 2 && points.rows > 0 &&
                  displacement.type == "double" && displacement.columns == 2 &&
                  displacement.rows == points.rows && von_mises.type == "double" &&
                  von_mises.columns == 1 && von_mises.rows == points.rows &&
                  elements.type == "int64" && elements.columns == 9 && elements.rows > 0 &&
                  quads.type == "int64" && quads.columns == 4 && quads.rows == 4 * elements.rows &&
                  file_->link_exists(kShellElementBar) &&
                  file_->link_exists(kShellQuadrilateralBar);
  if (!ok)
    throw IoError(
        fmt::format("{}: cannot resume: '{}' is not the shell of its snapshot", h5_path_, group));
  record.shell_nodes = points.rows;
  record.shell_elements = elements.rows;
}

// resume(): keeps the /xdmf/polygon_K_N the kept snapshots use, removes the others and writes
// any that is missing.
void SnapshotWriter::reconcile_polygons(const std::vector<SnapshotInfo>& kept) {
  std::set<std::pair<std::uint64_t, std::uint64_t>> used;
  for (const SnapshotInfo& r : kept)
    if (r.outline_vertices > 0) used.insert({r.outline_vertices, r.particles});
  for (const std::string& member : file_->group_members(kXdmfGroup)) {
    const auto size = polygon_size(member);
    if (!size) continue;
    const std::string path = kXdmfGroup + "/" + member;
    const h5::ParallelFile::DatasetShape shape = file_->dataset_shape(path);
    if (used.contains(*size) && shape.rows == size->second && shape.columns == size->first)
      polygon_sizes_.insert(*size);
    else
      file_->remove_link(path);
  }
  for (const auto& size : used) {
    if (polygon_sizes_.contains(size)) continue;
    write_polygons(size.first, h5::rank0_rows(comm_, size.second));
    polygon_sizes_.insert(size);
  }
}

// resume(): keeps the /xdmf/polyvertex_N the kept snapshots use (an unused one may be what a
// crash left half-written), removes the others and writes any that is missing.
void SnapshotWriter::reconcile_polyvertex(const std::vector<SnapshotInfo>& kept) {
  std::set<std::uint64_t> used;
  for (const SnapshotInfo& r : kept)
    if (r.particles > 0) used.insert(r.particles);
  for (const std::string& member : file_->group_members(kXdmfGroup)) {
    const std::optional<std::uint64_t> n = polyvertex_size(member);
    if (!n) continue;
    const std::string path = kXdmfGroup + "/" + member;
    if (used.contains(*n) && file_->dataset_shape(path).rows == *n)
      polyvertex_sizes_.insert(*n);
    else
      file_->remove_link(path);
  }
  for (const std::uint64_t n : used) {
    if (polyvertex_sizes_.contains(n)) continue;
    write_polyvertex(h5::rank0_rows(comm_, n));
    polyvertex_sizes_.insert(n);
  }
}

// Closes the file and syncs both files to disk: the file is opened once more (collectively)
// and flushed (MPI_File_sync), and rank 0 syncs snapshots.xmf and the folder.
void SnapshotWriter::close() {
  if (closed_) return;
  closed_ = true;
  std::string error;
  try {
    if (!file_) file_.emplace(h5::ParallelFile::open(comm_, h5_path_));
    file_->flush();
    file_->close();
  } catch (const IoError& e) {
    error = e.what();
  }
  file_.reset();
  mpi::agree_on_failure<IoError>(comm_, error);
  if (rank_ == 0 && written_ > 0) error = xdmf_->sync();
  mpi::agree_on_failure<IoError>(comm_, error);
}

}  // namespace dem2d
