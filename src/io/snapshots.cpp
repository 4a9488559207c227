#include "io/snapshots.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "core/errors.hpp"
#include "io/output_dir.hpp"

namespace dem2d {
namespace {

namespace fs = std::filesystem;

static_assert(sizeof(Vec2) == 2 * sizeof(double) && std::is_standard_layout_v<Vec2>,
              "a Vec2 array is written as an N x 2 array of doubles");

const double* as_doubles(const Field<Vec2>& f) { return reinterpret_cast<const double*>(f.data()); }

// The dataset that gives the XDMF grids their geometry; every other one is a point attribute.
constexpr const char* kGeometry = "position";

// A registry field as the writer sees it: its values, element type and values per particle.
struct Column {
  enum Element { kInt64, kInt32, kDouble } element;
  const void* data;
  std::size_t columns;
};

// The column types snapshots can hold; std::nullopt for any other.
std::optional<Column> column_of(const FieldBase& f) {
  if (const auto* d = dynamic_cast<const Field<double>*>(&f))
    return Column{Column::kDouble, d->data(), 1};
  if (const auto* v = dynamic_cast<const Field<Vec2>*>(&f))
    return Column{Column::kDouble, as_doubles(*v), 2};
  if (const auto* i = dynamic_cast<const Field<std::int64_t>*>(&f))
    return Column{Column::kInt64, i->data(), 1};
  if (const auto* i = dynamic_cast<const Field<std::int32_t>*>(&f))
    return Column{Column::kInt32, i->data(), 1};
  return std::nullopt;
}

const char* type_name(Column::Element e) {
  switch (e) {
    case Column::kInt64:
      return "int64";
    case Column::kInt32:
      return "int32";
    case Column::kDouble:
      break;
  }
  return "double";
}

// XDMF's NumberType and Precision of a SnapshotDataset::type.
std::pair<const char*, int> xdmf_number(const std::string& type) {
  if (type == "int64") return {"Int", 8};
  if (type == "int32") return {"Int", 4};
  return {"Float", 8};
}

void write_column(h5::ParallelFile& file, const std::string& name, const h5::RowRange& rows,
                  const Column& c) {
  switch (c.element) {
    case Column::kInt64:
      file.write_rows(name, rows, static_cast<const std::int64_t*>(c.data), c.columns);
      return;
    case Column::kInt32:
      file.write_rows(name, rows, static_cast<const std::int32_t*>(c.data), c.columns);
      return;
    case Column::kDouble:
      file.write_rows(name, rows, static_cast<const double*>(c.data), c.columns);
      return;
  }
}

// One XDMF DataItem that reads a whole dataset of snapshots.h5.
std::string hdf_item(const std::string& h5_name, const std::string& dataset, std::uint64_t rows,
                     int columns, const char* number_type, int precision) {
  const std::string dims =
      columns == 1 ? fmt::format("{}", rows) : fmt::format("{} {}", rows, columns);
  return fmt::format(
      R"(<DataItem Dimensions="{}" NumberType="{}" Precision="{}" Format="HDF">{}:{}</DataItem>)",
      dims, number_type, precision, h5_name, dataset);
}

// An attribute of the points: "Scalar" (N values) or "Vector" (N x 2 values). A 2-component
// vector is valid XDMF; ParaView's "XDMF Reader" pads it to 3 components (z = 0), its
// "Xdmf3 Reader S/T" keep 2 components.
std::string point_attribute(const std::string& attribute, const std::string& h5_name,
                            const std::string& dataset, std::uint64_t rows, int columns,
                            const char* number_type, int precision) {
  return fmt::format(
      "        <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Node\">\n"
      "          {}\n"
      "        </Attribute>\n",
      attribute, columns == 1 ? "Scalar" : "Vector",
      hdf_item(h5_name, dataset, rows, columns, number_type, precision));
}

// The dataset holding 0, 1, ..., n - 1: the connectivity of a Polyvertex topology of n points.
// The Xdmf3 readers make no cells without it (the points would not show as a surface).
std::string polyvertex_dataset(std::uint64_t n) { return fmt::format("/xdmf/polyvertex_{}", n); }

// Writes `text` to `path` through a temporary file and a rename, so that a reader never sees
// a half-written file. Returns an error message, empty on success.
std::string write_file_atomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr) return fmt::format("cannot create {}: {}", tmp, std::strerror(errno));
  const bool written = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const int write_errno = errno;
  if (std::fclose(f) != 0 || !written) {
    const int e = written ? errno : write_errno;
    std::remove(tmp.c_str());
    return fmt::format("cannot write {}: {}", tmp, std::strerror(e));
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) return fmt::format("cannot rename {} to {}: {}", tmp, path, ec.message());
  return {};
}

}  // namespace

std::vector<SnapshotDataset> snapshot_datasets(const ParticleStore& particles) {
  std::vector<SnapshotDataset> out;
  for (const FieldBase* f : particles.fields()) {
    if (!f->meta().snapshot) continue;
    const std::optional<Column> c = column_of(*f);
    if (!c)
      throw std::logic_error("SnapshotWriter: field '" + f->name() +
                             "' is marked for snapshots but its type cannot be written");
    out.push_back({f->name(), type_name(c->element), c->columns, f->meta().unit, f->meta().doc});
  }
  return out;
}

SnapshotWriter::SnapshotWriter(MPI_Comm comm, const std::string& directory,
                               const std::vector<MaterialSpec>& materials)
    : comm_(comm),
      h5_path_((fs::path(directory) / kSnapshotsFile).string()),
      xdmf_path_((fs::path(directory) / kXdmfFile).string()) {
  rank_ = mpi::rank(comm_);
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
      fs::remove(xdmf_path_, ec);  // a stale sidecar would point at groups no longer there
    }
  }
  mpi::agree_on_failure<IoError>(comm_, error);
  try {
    file_.emplace(h5::ParallelFile::create(comm_, h5_path_));
    write_materials(materials);
    file_->create_group("/snapshots");
    file_->create_group("/xdmf");
    file_->flush();
  } catch (const IoError& e) {
    error = e.what();
  }
  mpi::agree_on_failure<IoError>(comm_, error);
}

// Closes the file through the handle's destructor, which ignores (cannot report) a failure.
SnapshotWriter::~SnapshotWriter() = default;

void SnapshotWriter::write_materials(const std::vector<MaterialSpec>& materials) {
  file_->create_group("/materials");
  const h5::RowRange rows = h5::rank0_rows(comm_, materials.size());
  std::vector<std::string> names;
  for (const auto& m : materials) names.push_back(m.name);
  file_->write_strings("/materials/name", names);
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

void SnapshotWriter::write(const ParticleStore& p, double time, std::int64_t step,
                           std::span<const ExtraField> extra) {
  if (!file_) throw std::logic_error("SnapshotWriter::write after close");
  Record record{fmt::format("{:06d}", records_.size()), time, step, 0, snapshot_datasets(p)};
  for (const ExtraField& e : extra) {
    const bool taken = std::any_of(record.datasets.begin(), record.datasets.end(),
                                   [&](const SnapshotDataset& d) { return d.name == e.name; });
    if (e.values.size() != p.n_owned() || taken || e.name.empty())
      throw std::invalid_argument("SnapshotWriter: bad extra field '" + e.name + "'");
    record.datasets.push_back({e.name, "double", 1, e.unit, e.doc});
  }
  const std::string group = "/snapshots/" + record.name;
  std::string error;
  try {
    const h5::RowRange rows = h5::row_range(comm_, p.n_owned());
    record.particles = rows.total;
    file_->create_group(group);
    file_->write_attribute(group, "time", time);
    file_->write_attribute(group, "step", step);
    write_datasets(group, rows, p, extra);
    if (rows.total > 0 && !polyvertex_sizes_.contains(rows.total)) {
      std::vector<std::int64_t> index(rows.count);
      for (std::uint64_t i = 0; i < rows.count; ++i)
        index[i] = static_cast<std::int64_t>(rows.offset + i);
      file_->write_rows(polyvertex_dataset(rows.total), rows, index.data());
      polyvertex_sizes_.insert(rows.total);
    }
    file_->flush();  // a crash later still leaves this snapshot readable
  } catch (const IoError& e) {
    error = e.what();
  }
  mpi::agree_on_failure<IoError>(comm_, error);
  records_.push_back(std::move(record));
  if (rank_ == 0) error = write_xdmf();
  mpi::agree_on_failure<IoError>(comm_, error);
}

// The registry's snapshot fields in registry order, then the extra fields; each dataset with
// its unit and description as attributes, so a file explains itself.
void SnapshotWriter::write_datasets(const std::string& group, const h5::RowRange& rows,
                                    const ParticleStore& p, std::span<const ExtraField> extra) {
  const auto describe = [&](const std::string& name, const std::string& unit,
                            const std::string& doc) {
    file_->write_attribute(name, "unit", unit);
    file_->write_attribute(name, "doc", doc);
  };
  for (const FieldBase* f : p.fields()) {
    if (!f->meta().snapshot) continue;
    const std::string name = group + "/" + f->name();
    write_column(*file_, name, rows, *column_of(*f));  // snapshot_datasets checked the type
    describe(name, f->meta().unit, f->meta().doc);
  }
  for (const ExtraField& e : extra) {
    const std::string name = group + "/" + e.name;
    file_->write_rows(name, rows, e.values.data());
    describe(name, e.unit, e.doc);
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

std::string SnapshotWriter::write_xdmf() const {
  const std::string h5 = fs::path(h5_path_).filename().string();
  std::string text =
      "<?xml version=\"1.0\" ?>\n"
      "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
      "  <Domain>\n"
      "    <Grid Name=\"particles\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const Record& r : records_) {
    const std::string g = "/snapshots/" + r.name;
    const std::uint64_t n = r.particles;
    const std::string topology =
        n == 0
            ? "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"0\" NodesPerElement=\"1\"/>"
            : fmt::format(
                  "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\" "
                  "NodesPerElement=\"1\">\n          {}\n        </Topology>",
                  n, hdf_item(h5, polyvertex_dataset(n), n, 1, "Int", 8));
    text += fmt::format(
        "      <Grid Name=\"snapshot_{}\" GridType=\"Uniform\">\n"
        "        <Time Value=\"{:.17g}\"/>\n"
        "        {}\n"
        "        <Geometry GeometryType=\"XY\">\n"
        "          {}\n"
        "        </Geometry>\n",
        r.name, r.time, topology, hdf_item(h5, g + "/" + kGeometry, n, 2, "Float", 8));
    for (const SnapshotDataset& d : r.datasets) {
      if (d.name == kGeometry) continue;
      const auto [number_type, precision] = xdmf_number(d.type);
      text += point_attribute(d.name, h5, g + "/" + d.name, n, static_cast<int>(d.columns),
                              number_type, precision);
    }
    text += "      </Grid>\n";
  }
  text +=
      "    </Grid>\n"
      "  </Domain>\n"
      "</Xdmf>\n";
  return write_file_atomically(xdmf_path_, text);
}

}  // namespace dem2d
