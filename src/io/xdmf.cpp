// snapshots.xmf: the XDMF text of the snapshots that snapshots.h5 holds, and the file kept
// with it (xdmf.hpp).
#include "io/xdmf.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string_view>
#include <utility>

#include "io/output_dir.hpp"
#include "io/snapshot_layout.hpp"

namespace dem2d {
namespace {

namespace fs = std::filesystem;
using snapshot_layout::kGeometry;
using snapshot_layout::kMaterial;
using snapshot_layout::kOutlinesGroup;
using snapshot_layout::kShellGroup;
using snapshot_layout::kShellQuadrilateralBar;
using snapshot_layout::kShellQuadrilaterals;
using snapshot_layout::kSnapshotsGroup;
using snapshot_layout::kWallsGroup;
using snapshot_layout::material_lookup;
using snapshot_layout::polygon_dataset;
using snapshot_layout::polyvertex_dataset;

// snapshots.xmf is xdmf_header(), one grid per snapshot (xdmf_grid), kXdmfTrailer.
constexpr std::string_view kXdmfTrailer =
    "    </Grid>\n"
    "  </Domain>\n"
    "</Xdmf>\n";

// `text` with the five XML special characters escaped, for an attribute value.
std::string xml_escape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string xdmf_header(const std::vector<std::string>& material_names) {
  std::string text =
      "<?xml version=\"1.0\" ?>\n"
      "<Xdmf Version=\"3.0\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n"
      "  <Domain>\n";
  if (!material_names.empty())
    text += fmt::format("    <Information Name=\"material_names\" Value=\"{}\"/>\n",
                        xml_escape(material_lookup(material_names)));
  return text + "    <Grid Name=\"mill\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
}

// XDMF's NumberType and Precision of a SnapshotDataset::type.
std::pair<const char*, int> xdmf_number(const std::string& type) {
  if (type == "int64") return {"Int", 8};
  if (type == "int32") return {"Int", 4};
  return {"Float", 8};
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

// An attribute of the points (center "Node") or of the cells ("Cell"): "Scalar" (N values) or
// "Vector" (N x 2 values). A 2-component vector is valid XDMF; ParaView's "XDMF Reader" pads
// it to 3 components (z = 0), its "Xdmf3 Reader S/T" keep 2 components.
std::string attribute(const char* center, const std::string& attribute, const std::string& h5_name,
                      const std::string& dataset, std::uint64_t rows, int columns,
                      const char* number_type, int precision) {
  return fmt::format(
      "          <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"{}\">\n"
      "            {}\n"
      "          </Attribute>\n",
      attribute, columns == 1 ? "Scalar" : "Vector", center,
      hdf_item(h5_name, dataset, rows, columns, number_type, precision));
}

// The material names as field data (Center="Grid", one value in the file itself): ParaView
// lists an array "material: NAME" holding the material's row, in its Information panel and
// spreadsheet view, with every XDMF reader (none reads strings into field data).
std::string material_attributes(const std::vector<std::string>& material_names) {
  std::string text;
  for (std::size_t k = 0; k < material_names.size(); ++k)
    text += fmt::format(
        "          <Attribute Name=\"{}: {}\" AttributeType=\"Scalar\" Center=\"Grid\">\n"
        "            <DataItem Dimensions=\"1\" NumberType=\"Int\" Precision=\"4\" "
        "Format=\"XML\">{}</DataItem>\n"
        "          </Attribute>\n",
        kMaterial, xml_escape(material_names[k]), k);
  return text;
}

// The particles of one snapshot: a Polyvertex grid, position as the XY geometry, every other
// dataset as a point attribute, the material names as field data.
std::string particles_grid(const std::string& h5, const SnapshotInfo& r,
                           const std::vector<std::string>& material_names) {
  const std::string g = kSnapshotsGroup + "/" + r.name;
  const std::uint64_t n = r.particles;
  const std::string topology =
      n == 0
          ? "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"0\" NodesPerElement=\"1\"/>"
          : fmt::format(
                "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\" "
                "NodesPerElement=\"1\">\n            {}\n          </Topology>",
                n, hdf_item(h5, polyvertex_dataset(n), n, 1, "Int", 8));
  std::string text = fmt::format(
      "        <Grid Name=\"particles\" GridType=\"Uniform\">\n"
      "          {}\n"
      "          <Geometry GeometryType=\"XY\">\n"
      "            {}\n"
      "          </Geometry>\n",
      topology, hdf_item(h5, g + "/" + kGeometry, n, 2, "Float", 8));
  for (const SnapshotDataset& d : r.datasets) {
    if (d.name == kGeometry) continue;
    const auto [number_type, precision] = xdmf_number(d.type);
    text += attribute("Node", d.name, h5, g + "/" + d.name, n, static_cast<int>(d.columns),
                      number_type, precision);
  }
  return text + material_attributes(material_names) + "        </Grid>\n";
}

// The particles' outlines of one snapshot: a Polygon topology of K nodes per cell, one cell per
// particle (the connectivity /xdmf/polygon_K_N), the XY points /outlines/NNNNNN/points, and
// every dataset of the snapshot as a cell attribute (the cells are in the snapshot's row order:
// no data is repeated), the material names as field data.
std::string outlines_grid(const std::string& h5, const SnapshotInfo& r,
                          const std::vector<std::string>& material_names) {
  const std::string g = kSnapshotsGroup + "/" + r.name;
  const std::uint64_t n = r.particles, k = r.outline_vertices;
  std::string text = fmt::format(
      "        <Grid Name=\"outlines\" GridType=\"Uniform\">\n"
      "          <Topology TopologyType=\"Polygon\" NumberOfElements=\"{}\" "
      "NodesPerElement=\"{}\">\n"
      "            {}\n"
      "          </Topology>\n"
      "          <Geometry GeometryType=\"XY\">\n"
      "            {}\n"
      "          </Geometry>\n",
      n, k, hdf_item(h5, polygon_dataset(k, n), n, static_cast<int>(k), "Int", 8),
      hdf_item(h5, kOutlinesGroup + "/" + r.name + "/points", n * k, 2, "Float", 4));
  for (const SnapshotDataset& d : r.datasets) {
    const auto [number_type, precision] = xdmf_number(d.type);
    text += attribute("Cell", d.name, h5, g + "/" + d.name, n, static_cast<int>(d.columns),
                      number_type, precision);
  }
  return text + material_attributes(material_names) + "        </Grid>\n";
}

// The wall outline of one snapshot: line segments (a Polyline topology of 2 nodes per element,
// the connectivity /walls/NNNNNN/segments) between the XY points /walls/NNNNNN/points.
std::string walls_grid(const std::string& h5, const SnapshotInfo& r) {
  const std::string g = kWallsGroup + "/" + r.name;
  return fmt::format(
      "        <Grid Name=\"walls\" GridType=\"Uniform\">\n"
      "          <Topology TopologyType=\"Polyline\" NumberOfElements=\"{}\" "
      "NodesPerElement=\"2\">\n"
      "            {}\n"
      "          </Topology>\n"
      "          <Geometry GeometryType=\"XY\">\n"
      "            {}\n"
      "          </Geometry>\n"
      "        </Grid>\n",
      r.wall_segments, hdf_item(h5, g + "/segments", r.wall_segments, 2, "Int", 8),
      hdf_item(h5, g + "/points", r.wall_points, 2, "Float", 8));
}

// The shell of one snapshot: its 9-node elements drawn as four 4-node quadrilaterals each (a
// Quadrilateral topology, the connectivity /shell_mesh/quadrilaterals) over the XY points
// /shell/NNNNNN/points, the displacement as a point vector, von Mises as a point scalar, and
// each quadrilateral's bar as a cell scalar.
std::string shell_grid(const std::string& h5, const SnapshotInfo& r) {
  const std::string g = kShellGroup + "/" + r.name;
  const std::uint64_t m = r.shell_nodes, quads = 4 * r.shell_elements;
  return fmt::format(
             "        <Grid Name=\"shell\" GridType=\"Uniform\">\n"
             "          <Topology TopologyType=\"Quadrilateral\" NumberOfElements=\"{}\" "
             "NodesPerElement=\"4\">\n"
             "            {}\n"
             "          </Topology>\n"
             "          <Geometry GeometryType=\"XY\">\n"
             "            {}\n"
             "          </Geometry>\n",
             quads, hdf_item(h5, kShellQuadrilaterals, quads, 4, "Int", 8),
             hdf_item(h5, g + "/points", m, 2, "Float", 8)) +
         attribute("Node", "displacement", h5, g + "/displacement", m, 2, "Float", 8) +
         attribute("Node", "von_mises", h5, g + "/von_mises", m, 1, "Float", 8) +
         attribute("Cell", "bar", h5, kShellQuadrilateralBar, quads, 1, "Int", 8) +
         "        </Grid>\n";
}

// The <Grid> of one snapshot in snapshots.xmf, a spatial collection at the snapshot's time of
// the particles, (when the snapshot has them) the particles' outlines, (when the snapshot
// has one) the wall outline and (when it has one) the shell; `h5` is the HDF5 file's name.
// ParaView's three XDMF readers show it as a multiblock of one block per grid at each time step.
std::string xdmf_grid(const std::string& h5, const SnapshotInfo& r,
                      const std::vector<std::string>& material_names) {
  std::string text = fmt::format(
      "      <Grid Name=\"snapshot_{}\" GridType=\"Collection\" CollectionType=\"Spatial\">\n"
      "        <Time Value=\"{:.17g}\"/>\n",
      r.name, r.time);
  text += particles_grid(h5, r, material_names);
  if (r.outline_vertices > 0) text += outlines_grid(h5, r, material_names);
  if (r.wall_segments > 0) text += walls_grid(h5, r);
  if (r.shell_nodes > 0) text += shell_grid(h5, r);
  return text + "      </Grid>\n";
}

// Writes all of `text` at `offset` of the open file `fd`; false (errno set) on failure.
bool write_at(int fd, std::string_view text, off_t offset) {
  while (!text.empty()) {
    const ssize_t n = ::pwrite(fd, text.data(), text.size(), offset);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (n == 0) errno = EIO;
      return false;
    }
    text.remove_prefix(static_cast<std::size_t>(n));
    offset += n;
  }
  return true;
}

}  // namespace

std::string XdmfSidecar::rewrite(const std::vector<SnapshotInfo>& snapshots,
                                 const std::vector<std::string>& material_names) {
  trailer_.reset();
  if (snapshots.empty()) {  // nothing to show
    std::error_code ec;
    fs::remove(path_, ec);
    return ec ? fmt::format("cannot remove {}: {}", path_, ec.message()) : std::string();
  }
  std::string text = xdmf_header(material_names);
  for (const SnapshotInfo& r : snapshots) text += xdmf_grid(h5_name_, r, material_names);
  const auto trailer_at = static_cast<long>(text.size());
  text += kXdmfTrailer;
  std::string error = write_file_atomically(path_, text);
  if (error.empty()) trailer_ = trailer_at;
  return error;
}

bool XdmfSidecar::can_append() const {
  std::error_code ec;
  return trailer_.has_value() && fs::is_regular_file(path_, ec);
}

// O(1): the new grid and the trailer over the old trailer. On a failure the old trailer is put
// back and the file cut after it (best effort), and the next snapshot rewrites the file whole.
std::string XdmfSidecar::append(const SnapshotInfo& snapshot,
                                const std::vector<std::string>& material_names) {
  const int fd = ::open(path_.c_str(), O_WRONLY | O_CLOEXEC);
  if (fd < 0 || !trailer_) {
    const int error = errno;
    if (fd >= 0) ::close(fd);
    trailer_.reset();
    return fmt::format("cannot open {}: {}", path_, std::strerror(error));
  }
  const auto at = static_cast<off_t>(*trailer_);
  trailer_.reset();  // until the write succeeded
  const std::string grid = xdmf_grid(h5_name_, snapshot, material_names);
  bool ok = write_at(fd, grid + std::string(kXdmfTrailer), at);
  int error = errno;
  if (!ok && write_at(fd, kXdmfTrailer, at))
    (void)!::ftruncate(fd, at + static_cast<off_t>(kXdmfTrailer.size()));
  if (::close(fd) != 0 && ok) {
    ok = false;
    error = errno;
  }
  if (!ok) return fmt::format("cannot write {}: {}", path_, std::strerror(error));
  trailer_ = static_cast<long>(at) + static_cast<long>(grid.size());
  return {};
}

namespace {

// fsync of the file or folder `path`; an error message, empty on success.
std::string sync_path(const std::string& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return fmt::format("cannot open {}: {}", path, std::strerror(errno));
  const bool ok = ::fsync(fd) == 0;
  const int error = errno;
  ::close(fd);
  return ok ? std::string() : fmt::format("cannot sync {}: {}", path, std::strerror(error));
}

}  // namespace

std::string XdmfSidecar::sync() const {
  std::error_code ec;
  if (!fs::exists(path_, ec)) return {};
  std::string error = sync_path(path_, O_RDONLY);
  if (!error.empty()) return error;
  const fs::path folder = fs::path(path_).parent_path();
  return sync_path(folder.empty() ? "." : folder.string(), O_RDONLY | O_DIRECTORY);
}

}  // namespace dem2d
