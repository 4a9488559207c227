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
#include <map>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "core/base/errors.hpp"
#include "io/output_dir.hpp"
#include "io/snapshot_layout.hpp"
#include "io/xdmf.hpp"

namespace dem2d {
namespace {

namespace fs = std::filesystem;
using snapshot_layout::kGeometry;
using snapshot_layout::kMaterial;
using snapshot_layout::kSnapshotsGroup;
using snapshot_layout::kWallsGroup;
using snapshot_layout::kXdmfGroup;
using snapshot_layout::material_lookup;
using snapshot_layout::polyvertex_dataset;

// The derived dataset every snapshot holds after the registry's: |velocity|.
const SnapshotDataset kSpeed{"speed", "double", 1, "m/s",
                             "speed of the centre, the norm of velocity"};

// The group of the snapshot being written (snapshots.h5's other groups: snapshot_layout.hpp).
const std::string kStagingGroup = "/incomplete";

// Where snapshot NAME's wall outline is staged (beside its particles, /incomplete/NAME).
std::string staged_walls(const std::string& name) { return kStagingGroup + "/walls_" + name; }

// The n of a member "polyvertex_n" of /xdmf; std::nullopt for another name.
std::optional<std::uint64_t> polyvertex_size(const std::string& member) {
  const std::string prefix = "polyvertex_";
  if (!member.starts_with(prefix) || member.size() == prefix.size()) return std::nullopt;
  const std::string digits = member.substr(prefix.size());
  if (digits.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  return std::stoull(digits);
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
    file_->flush();
  } catch (const IoError& e) {
    error = e.what();
  }
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
  std::string error;
  try {
    w->file_.emplace(h5::ParallelFile::open(comm, path));
    w->drop_and_read(time + tolerance);
    w->file_->flush();
  } catch (const IoError& e) {
    error = e.what();
  }
  w->agree(error);
  if (w->rank_ == 0) error = w->xdmf_->rewrite(w->records_, w->material_names_);
  w->agree(error);
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

void SnapshotWriter::write(const ParticleStore& p, double time, std::int64_t step,
                           std::span<const std::vector<Vec2>> walls,
                           std::span<const ExtraField> extra) {
  if (!file_) throw std::logic_error("SnapshotWriter::write after close");
  SnapshotInfo record = describe(p, time, step, extra);
  const WallData outline = wall_data(walls);
  std::array<int, 2> wall_rows{static_cast<int>(outline.points.size() / 2),
                               static_cast<int>(outline.segments.size() / 2)};
  mpi::broadcast(comm_, wall_rows, 0);  // rank 0's outline is written
  record.wall_points = static_cast<std::uint64_t>(wall_rows[0]);
  record.wall_segments = static_cast<std::uint64_t>(wall_rows[1]);
  std::uint64_t row_bytes = 0;
  for (const SnapshotDataset& d : record.datasets)
    row_bytes += d.columns * (d.type == "int32" ? 4 : 8);
  const std::uint64_t total = h5::row_range(comm_, p.n_owned()).total;
  ensure_free_space(comm_, h5_path_,
                    total * row_bytes + 16 * (record.wall_points + record.wall_segments) +
                        2048 * (record.datasets.size() + 2) + 16384);
  const std::string staged = kStagingGroup + "/" + record.name;
  const std::string published = kSnapshotsGroup + "/" + record.name;
  std::string error;
  try {
    if (failed_) clear_failed_write(record.name);
    const h5::RowRange rows = h5::row_range(comm_, p.n_owned());
    record.particles = rows.total;
    stage(staged, record, rows, p, extra, outline);
  } catch (const IoError& e) {
    error = e.what();
  }
  agree(error);
  try {
    if (record.wall_segments > 0)  // the outline first: a published snapshot has its outline
      file_->move_link(staged_walls(record.name), kWallsGroup + "/" + record.name);
    file_->move_link(staged, published);  // complete: readers may see it from now on
    file_->flush();                       // a crash later still leaves this snapshot readable
  } catch (const IoError& e) {
    error = e.what();
  }
  agree(error);
  if (record.particles > 0) polyvertex_sizes_.insert(record.particles);
  records_.push_back(std::move(record));
  ++next_index_;
  if (rank_ == 0) error = xdmf_->append(records_, material_names_);
  agree(error);
}

void SnapshotWriter::agree(const std::string& local_error) {
  std::string message = mpi::first_failure(comm_, local_error);
  if (message.empty()) return;
  failed_ = true;
  throw IoError(message);
}

// Before the write after a failed one: removes what the failed write of snapshot `name` left
// (its staging groups; its published groups if it failed after a move, before it was
// recorded; a connectivity dataset no recorded snapshot uses), so the write can start afresh.
void SnapshotWriter::clear_failed_write(const std::string& name) {
  for (const std::string& g : {kStagingGroup + "/" + name, staged_walls(name),
                               kSnapshotsGroup + "/" + name, kWallsGroup + "/" + name})
    if (file_->link_exists(g)) file_->remove_link(g);
  for (const std::string& member : file_->group_members(kXdmfGroup)) {
    const std::optional<std::uint64_t> n = polyvertex_size(member);
    if (n && !polyvertex_sizes_.contains(*n)) file_->remove_link(kXdmfGroup + "/" + member);
  }
  failed_ = false;
}

// The snapshot as the staging group `group`, with the connectivity it needs and its wall
// outline (staged_walls), flushed.
void SnapshotWriter::stage(const std::string& group, const SnapshotInfo& record,
                           const h5::RowRange& rows, const ParticleStore& p,
                           std::span<const ExtraField> extra, const WallData& walls) {
  file_->create_group(group, /*track_order=*/true);  // resume() reads the datasets in order
  file_->write_attribute(group, "time", record.time);
  file_->write_attribute(group, "step", record.step);
  write_datasets(group, rows, p, extra);
  if (rows.total > 0 && !polyvertex_sizes_.contains(rows.total)) write_polyvertex(rows);
  if (record.wall_segments > 0) write_walls(staged_walls(record.name), record, walls);
  if (fail_before_dataset_) {  // testing: past the last dataset, fail before the flush
    fail_before_dataset_.reset();
    throw IoError(fmt::format("{}: cannot flush '{}': injected failure", h5_path_, group));
  }
  file_->flush();
}

// The registry's snapshot fields in registry order, then speed, then the extra fields; each
// dataset with its unit and description as attributes, so a file explains itself, and the
// material rows with the material names (attribute `names`, "0=steel,1=ore").
void SnapshotWriter::write_datasets(const std::string& group, const h5::RowRange& rows,
                                    const ParticleStore& p, std::span<const ExtraField> extra) {
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
    file_->write_field(name, rows, *f);  // snapshot_datasets checked the type
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
// (M x 2) and the segments (S x 2 point rows); rank 0's, the same on every rank.
void SnapshotWriter::write_walls(const std::string& group, const SnapshotInfo& record,
                                 const WallData& walls) {
  file_->create_group(group);
  file_->write_attribute(group, "time", record.time);
  file_->write_attribute(group, "step", record.step);
  const std::string points = group + "/points";
  file_->write_rows(points, h5::rank0_rows(comm_, record.wall_points), walls.points.data(), 2);
  file_->write_attribute(points, "unit", std::string("m"));
  file_->write_attribute(points, "doc", std::string("x and y of the outline's points, lab frame"));
  const std::string segments = group + "/segments";
  file_->write_rows(segments, h5::rank0_rows(comm_, record.wall_segments), walls.segments.data(),
                    2);
  file_->write_attribute(segments, "unit", std::string("1"));
  file_->write_attribute(segments, "doc",
                         std::string("rows of `points` joined by each straight piece"));
}

// /xdmf/polyvertex_N for N = rows.total: 0, 1, ..., N - 1, each rank writing its rows.
void SnapshotWriter::write_polyvertex(const h5::RowRange& rows) {
  std::vector<std::int64_t> index(rows.count);
  for (std::uint64_t i = 0; i < rows.count; ++i)
    index[i] = static_cast<std::int64_t>(rows.offset + i);
  file_->write_rows(polyvertex_dataset(rows.total), rows, index.data());
}

// resume(): empties /incomplete, drops the snapshots after `last_time`, records the others in
// order and makes /xdmf hold exactly the connectivity they use.
void SnapshotWriter::drop_and_read(double last_time) {
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
  for (const auto& [index, name] : groups) {
    std::optional<SnapshotInfo> record = read_record(name, last_time);
    if (!record) {
      file_->remove_link(kSnapshotsGroup + "/" + name);
      continue;
    }
    records_.push_back(std::move(*record));
    next_index_ = index + 1;
  }
  reconcile_polyvertex();
  reconcile_walls();
}

// The snapshot /snapshots/NAME as the file holds it; std::nullopt when its time is after
// `last_time`. Throws IoError for a group that is not a snapshot dem2d wrote.
std::optional<SnapshotInfo> SnapshotWriter::read_record(const std::string& name, double last_time) {
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
void SnapshotWriter::reconcile_walls() {
  std::map<std::string, SnapshotInfo*> kept;
  for (SnapshotInfo& r : records_) kept[r.name] = &r;
  for (const std::string& member : file_->group_members(kWallsGroup)) {
    const std::string group = kWallsGroup + "/" + member;
    const auto it = kept.find(member);
    if (it == kept.end()) {
      file_->remove_link(group);
      continue;
    }
    const bool complete =
        file_->link_exists(group + "/points") && file_->link_exists(group + "/segments");
    const h5::ParallelFile::DatasetShape points =
        complete ? file_->dataset_shape(group + "/points") : h5::ParallelFile::DatasetShape{};
    const h5::ParallelFile::DatasetShape segments =
        complete ? file_->dataset_shape(group + "/segments") : h5::ParallelFile::DatasetShape{};
    if (!complete || points.type != "double" || points.columns != 2 || segments.type != "int64" ||
        segments.columns != 2 || segments.rows == 0)
      throw IoError(fmt::format("{}: cannot resume: '{}' is not a wall outline", h5_path_, group));
    it->second->wall_points = points.rows;
    it->second->wall_segments = segments.rows;
  }
}

// resume(): keeps the /xdmf/polyvertex_N the kept snapshots use (an unused one may be what a
// crash left half-written), removes the others and writes any that is missing.
void SnapshotWriter::reconcile_polyvertex() {
  std::set<std::uint64_t> used;
  for (const SnapshotInfo& r : records_)
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

void SnapshotWriter::close() {
  if (!file_) return;
  std::string error;
  try {
    file_->close();
  } catch (const IoError& e) {
    error = e.what();
  }
  file_.reset();
  mpi::agree_on_failure<IoError>(comm_, error);
}

}  // namespace dem2d
