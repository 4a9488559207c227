// Output files: snapshots.h5 (+ snapshots.xmf), series.csv and the output directory.
// Runs on any number of ranks (mpirun -np 1, 2, 3): each rank owns a contiguous block of the
// particles (or, in one test, none), and the file must hold them in rank order.
// Set DEM2D_KEEP_TEST_OUTPUT=1 to keep the files (rank 0 prints where they are).
#include <gtest/gtest.h>
#include <hdf5.h>
#include <mpi.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "core/base/errors.hpp"
#include "core/base/scene.hpp"
#include "core/run/simulation.hpp"
#include "core/shape/outline.hpp"
#include "core/shape/particles.hpp"
#include "core/shape/superellipse.hpp"
#include "io/hdf5.hpp"
#include "io/lifter_log.hpp"
#include "io/output_dir.hpp"
#include "io/series.hpp"
#include "io/snapshots.hpp"
#include "parallel/mpi_domain.hpp"
#include "support/thesis.hpp"

namespace dem2d {
namespace {

namespace fs = std::filesystem;

int comm_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

int comm_size() {
  int s = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &s);
  return s;
}

// Rank 0's copy of `s` on every rank.
std::string rank0_string(std::string s) {
  unsigned long n = s.size();
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG, 0, MPI_COMM_WORLD);
  s.resize(n);
  MPI_Bcast(s.data(), static_cast<int>(n), MPI_CHAR, 0, MPI_COMM_WORLD);
  return s;
}

// A fresh directory that all ranks share, removed at the end unless DEM2D_KEEP_TEST_OUTPUT.
class ScratchDir {
 public:
  ScratchDir() {
    std::string path;
    if (comm_rank() == 0) {
      std::string pattern = (fs::path(testing::TempDir()) / "dem2d_io_XXXXXX").string();
      if (::mkdtemp(pattern.data()) == nullptr) std::abort();
      path = pattern;
    }
    path_ = rank0_string(path);
  }
  ~ScratchDir() {
    MPI_Barrier(MPI_COMM_WORLD);
    if (comm_rank() != 0) return;
    if (std::getenv("DEM2D_KEEP_TEST_OUTPUT") != nullptr) {
      std::printf("[ kept     ] %s\n", path_.c_str());
    } else {
      std::error_code ec;
      fs::remove_all(path_, ec);
    }
  }
  const std::string& path() const { return path_; }
  std::string operator/(const std::string& name) const { return (fs::path(path_) / name).string(); }

 private:
  std::string path_;
};

std::vector<MaterialSpec> test_materials() {
  const MaterialSpec steel = testing_support::thesis_steel();
  MaterialSpec ore;
  ore.name = "iron ore";
  ore.density = 3500.0;
  ore.youngs_modulus = 5.0e10;
  ore.poisson_ratio = 0.3;
  ore.shear_modulus = 5.0e10 / 2.6;
  ore.restitution = 0.5;
  ore.sliding_friction = 0.6;
  ore.rolling_friction = 0.1;
  MaterialSpec liner;
  liner.name = "rubber-liner";
  liner.density = 1100.0;
  liner.youngs_modulus = 1.0e7;
  liner.poisson_ratio = 0.45;
  liner.shear_modulus = 1.0e7 / 2.9;
  liner.restitution = 0.4;
  liner.sliding_friction = 0.9;
  liner.rolling_friction = 0.02;
  return {steel, ore, liner};
}

// The values of global particle k in snapshot `version` (distinct ids, materials, values
// that are not round in binary).
struct Expected {
  std::int64_t id;
  std::int32_t material;
  Vec2 pos, vel;
  double spin, radius, angle;
};

Expected expected(int k, int version) {
  const double v = version;
  return {1000 + 37 * k,
          static_cast<std::int32_t>(k % 3),
          {0.1 * k + 1.0 / 3.0 + v, -0.2 * k - v / 7.0},
          {1.5 * k - v, -k / 7.0 + 0.01 * v},
          0.3 * k - 1.0 + v / 3.0,
          0.01 * (k + 1),
          -0.7 * k + v / 9.0};
}

double damage(int k) { return k / 11.0; }

// Rank that owns global particle k when `n` particles are split in contiguous blocks.
int block_owner(int k, int n) { return static_cast<int>(static_cast<long>(k) * comm_size() / n); }

// Fills `store` with this rank's particles (owner(k) == rank) of snapshot `version`, then
// adds two ghosts with junk values, which must not be written.
template <class Owner>
std::vector<double> fill(ParticleStore& store, int n, int version, Owner owner) {
  std::vector<double> dmg;
  for (int k = 0; k < n; ++k) {
    if (owner(k) != comm_rank()) continue;
    const Expected e = expected(k, version);
    const std::size_t i = store.add(e.id, e.material, e.radius, 7800.0, e.pos, e.vel, e.spin);
    store.theta[i] = e.angle;
    dmg.push_back(damage(k));
  }
  const std::size_t g = store.add_ghosts(2);
  for (std::size_t i = g; i < store.size(); ++i) {
    store.id[i] = -1;
    store.pos[i] = {1e9, 1e9};
  }
  return dmg;
}

// --- Reading with the plain HDF5 C API (rank 0, after the writer is closed) ---------------

struct H5Closer {
  hid_t id;
  herr_t (*close)(hid_t);
  ~H5Closer() {
    if (id >= 0) close(id);
  }
};

template <class T>
std::vector<T> read_dataset(hid_t file, const std::string& name, hid_t memory_type,
                            std::vector<hsize_t>& dims) {
  H5Closer d{H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose};
  EXPECT_GE(d.id, 0) << name;
  if (d.id < 0) return {};
  H5Closer s{H5Dget_space(d.id), H5Sclose};
  const int rank = H5Sget_simple_extent_ndims(s.id);
  dims.assign(static_cast<std::size_t>(rank), 0);
  H5Sget_simple_extent_dims(s.id, dims.data(), nullptr);
  const auto n = static_cast<std::size_t>(H5Sget_simple_extent_npoints(s.id));
  std::vector<T> values(n);
  if (n > 0) {
    EXPECT_GE(H5Dread(d.id, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0);
  }
  return values;
}

template <class T>
T read_attribute(hid_t file, const std::string& object, const std::string& name, hid_t type) {
  H5Closer a{H5Aopen_by_name(file, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
             H5Aclose};
  EXPECT_GE(a.id, 0) << object << "@" << name;
  T value{};
  if (a.id >= 0) {
    EXPECT_GE(H5Aread(a.id, type, &value), 0);
  }
  return value;
}

std::vector<std::string> read_strings(hid_t file, const std::string& name) {
  H5Closer d{H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose};
  EXPECT_GE(d.id, 0) << name;
  if (d.id < 0) return {};
  H5Closer t{H5Dget_type(d.id), H5Tclose};
  EXPECT_EQ(H5Tget_class(t.id), H5T_STRING);
  EXPECT_EQ(H5Tis_variable_str(t.id), 0);
  const std::size_t width = H5Tget_size(t.id);
  H5Closer s{H5Dget_space(d.id), H5Sclose};
  const auto n = static_cast<std::size_t>(H5Sget_simple_extent_npoints(s.id));
  std::vector<char> buffer(n * width);
  if (n > 0) {
    EXPECT_GE(H5Dread(d.id, t.id, H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer.data()), 0);
  }
  std::vector<std::string> out;
  for (std::size_t i = 0; i < n; ++i)
    out.emplace_back(buffer.data() + i * width, strnlen(buffer.data() + i * width, width));
  return out;
}

// A fixed-length string attribute (what ParallelFile::write_attribute writes for a string).
std::string read_string_attribute(hid_t file, const std::string& object, const std::string& name) {
  H5Closer a{H5Aopen_by_name(file, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
             H5Aclose};
  EXPECT_GE(a.id, 0) << object << "@" << name;
  if (a.id < 0) return {};
  H5Closer t{H5Aget_type(a.id), H5Tclose};
  EXPECT_EQ(H5Tget_class(t.id), H5T_STRING) << object << "@" << name;
  EXPECT_EQ(H5Tis_variable_str(t.id), 0);
  const std::size_t width = H5Tget_size(t.id);
  std::vector<char> buffer(width + 1, '\0');
  EXPECT_GE(H5Aread(a.id, t.id, buffer.data()), 0);
  return std::string(buffer.data(), strnlen(buffer.data(), width));
}

// The names of the members of group `name`.
std::set<std::string> group_members(hid_t file, const std::string& name) {
  std::set<std::string> out;
  H5Literate_by_name(
      file, name.c_str(), H5_INDEX_NAME, H5_ITER_INC, nullptr,
      [](hid_t, const char* member, const H5L_info_t*, void* data) -> herr_t {
        static_cast<std::set<std::string>*>(data)->insert(member);
        return 0;
      },
      &out, H5P_DEFAULT);
  return out;
}

using Dims = std::vector<hsize_t>;

// Checks /snapshots/NAME against particles [0, n) of `version`, all values exactly.
void check_snapshot(hid_t file, const std::string& name, int n, int version, double time,
                    std::int64_t step) {
  SCOPED_TRACE("snapshot " + name);
  const std::string g = "/snapshots/" + name;
  EXPECT_EQ(read_attribute<double>(file, g, "time", H5T_NATIVE_DOUBLE), time);
  EXPECT_EQ(read_attribute<std::int64_t>(file, g, "step", H5T_NATIVE_INT64), step);
  const auto un = static_cast<hsize_t>(n);
  Dims dims;
  const auto id = read_dataset<std::int64_t>(file, g + "/id", H5T_NATIVE_INT64, dims);
  EXPECT_EQ(dims, (Dims{un}));
  const auto pos = read_dataset<double>(file, g + "/position", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (Dims{un, 2}));
  const auto vel = read_dataset<double>(file, g + "/velocity", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (Dims{un, 2}));
  const auto spin = read_dataset<double>(file, g + "/spin", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (Dims{un}));
  const auto radius = read_dataset<double>(file, g + "/radius", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (Dims{un}));
  const auto material = read_dataset<std::int32_t>(file, g + "/material", H5T_NATIVE_INT32, dims);
  EXPECT_EQ(dims, (Dims{un}));
  const auto angle = read_dataset<double>(file, g + "/angle", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (Dims{un}));
  const auto speed = read_dataset<double>(file, g + "/speed", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (Dims{un}));
  ASSERT_EQ(id.size(), un);
  ASSERT_EQ(angle.size(), un);
  ASSERT_EQ(pos.size(), 2 * un);
  ASSERT_EQ(vel.size(), 2 * un);
  ASSERT_EQ(spin.size(), un);
  ASSERT_EQ(radius.size(), un);
  ASSERT_EQ(material.size(), un);
  ASSERT_EQ(speed.size(), un);
  for (int k = 0; k < n; ++k) {
    const Expected e = expected(k, version);
    const auto i = static_cast<std::size_t>(k);
    EXPECT_EQ(id[i], e.id) << "k=" << k;
    EXPECT_EQ(material[i], e.material) << "k=" << k;
    EXPECT_EQ(pos[2 * i], e.pos.x) << "k=" << k;
    EXPECT_EQ(pos[2 * i + 1], e.pos.y) << "k=" << k;
    EXPECT_EQ(vel[2 * i], e.vel.x) << "k=" << k;
    EXPECT_EQ(vel[2 * i + 1], e.vel.y) << "k=" << k;
    EXPECT_EQ(spin[i], e.spin) << "k=" << k;
    EXPECT_EQ(radius[i], e.radius) << "k=" << k;
    EXPECT_EQ(angle[i], e.angle) << "k=" << k;
    EXPECT_EQ(speed[i], std::sqrt(e.vel.x * e.vel.x + e.vel.y * e.vel.y)) << "k=" << k;
  }
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Minimal well-formedness: every element closes, in order. Returns "" or the problem.
std::string xml_problem(const std::string& text) {
  std::vector<std::string> open;
  std::size_t i = 0;
  while ((i = text.find('<', i)) != std::string::npos) {
    const std::size_t end = text.find('>', i);
    if (end == std::string::npos) return "unterminated tag";
    const std::string tag = text.substr(i + 1, end - i - 1);
    i = end + 1;
    if (tag.empty() || tag[0] == '?' || tag[0] == '!') continue;
    if (tag[0] == '/') {
      if (open.empty() || open.back() != tag.substr(1))
        return "unexpected </" + tag.substr(1) + ">";
      open.pop_back();
    } else if (tag.back() != '/') {
      open.push_back(tag.substr(0, tag.find_first_of(" \t\n")));
    }
  }
  return open.empty() ? "" : "unclosed <" + open.back() + ">";
}

// Every value of `<Time Value="..."`: the times of the snapshots of a sidecar.
std::vector<std::string> time_values(const std::string& text) {
  std::vector<std::string> out;
  const std::string key = "<Time Value=\"";
  for (std::size_t i = 0; (i = text.find(key, i)) != std::string::npos;) {
    i += key.size();
    out.push_back(text.substr(i, text.find('"', i) - i));
  }
  return out;
}

// Every value of `attribute="..."` in `text`.
std::vector<std::string> attribute_values(const std::string& text, const std::string& attribute) {
  std::vector<std::string> out;
  const std::string key = " " + attribute + "=\"";
  for (std::size_t i = 0; (i = text.find(key, i)) != std::string::npos;) {
    i += key.size();
    out.push_back(text.substr(i, text.find('"', i) - i));
  }
  return out;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t i = 0; (i = text.find(what, i)) != std::string::npos; i += what.size()) ++n;
  return n;
}

// --- snapshots.h5 -----------------------------------------------------------------------

TEST(SnapshotWriter, TwoSnapshotsRoundTripExactly) {
  ScratchDir dir;
  const int n = 5;
  const double t0 = 0.1, t1 = 0.25 + 1e-12;
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    ParticleStore a;
    fill(a, n, 0, [&](int k) { return block_owner(k, n); });
    writer.write(a, t0, 10000);
    ParticleStore b;
    const std::vector<double> dmg = fill(b, n, 1, [&](int k) { return block_owner(k, n); });
    const ExtraField extra[] = {{"damage", dmg}};
    writer.write(b, t1, 25000, {}, extra);
    EXPECT_EQ(writer.snapshots_written(), 2u);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;

  H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  check_snapshot(file.id, "000000", n, 0, t0, 10000);
  check_snapshot(file.id, "000001", n, 1, t1, 25000);
  EXPECT_GT(H5Lexists(file.id, "/snapshots/000001/damage", H5P_DEFAULT), 0);
  EXPECT_EQ(H5Lexists(file.id, "/snapshots/000000/damage", H5P_DEFAULT), 0);
  EXPECT_EQ(H5Lexists(file.id, "/snapshots/000002", H5P_DEFAULT), 0);
  Dims dims;
  const auto dmg =
      read_dataset<double>(file.id, "/snapshots/000001/damage", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (Dims{static_cast<hsize_t>(n)}));
  for (int k = 0; k < n && static_cast<std::size_t>(k) < dmg.size(); ++k)
    EXPECT_EQ(dmg[static_cast<std::size_t>(k)], damage(k));

  // The materials table.
  const auto materials = test_materials();
  EXPECT_EQ(read_strings(file.id, "/materials/name"),
            (std::vector<std::string>{"steel", "iron ore", "rubber-liner"}));
  auto column = [&](const char* name, double MaterialSpec::*member) {
    Dims d;
    const auto v =
        read_dataset<double>(file.id, std::string("/materials/") + name, H5T_NATIVE_DOUBLE, d);
    ASSERT_EQ(v.size(), materials.size()) << name;
    for (std::size_t i = 0; i < v.size(); ++i) EXPECT_EQ(v[i], materials[i].*member) << name;
  };
  column("density", &MaterialSpec::density);
  column("youngs_modulus", &MaterialSpec::youngs_modulus);
  column("poisson_ratio", &MaterialSpec::poisson_ratio);
  column("shear_modulus", &MaterialSpec::shear_modulus);
  column("restitution", &MaterialSpec::restitution);
  column("sliding_friction", &MaterialSpec::sliding_friction);
  column("rolling_friction", &MaterialSpec::rolling_friction);

  // The XDMF sidecar: well formed, one spatial collection per snapshot with its time holding
  // the particles' Uniform grid (no outline given: no walls grid), every heavy-data path
  // present in the HDF5 file.
  ASSERT_TRUE(fs::exists(dir / "snapshots.xmf"));
  EXPECT_FALSE(fs::exists(dir / "snapshots.xmf.tmp"));
  const std::string xmf = read_text(dir / "snapshots.xmf");
  EXPECT_EQ(xml_problem(xmf), "");
  EXPECT_NE(xmf.find("<Xdmf Version=\"3.0\""), std::string::npos);
  EXPECT_EQ(count(xmf, "<Grid "), 5u);  // the temporal collection, two snapshots of one grid
  EXPECT_EQ(count(xmf, "GridType=\"Uniform\""), 2u);
  EXPECT_EQ(count(xmf, "CollectionType=\"Temporal\""), 1u);
  EXPECT_EQ(count(xmf, "CollectionType=\"Spatial\""), 2u);
  EXPECT_EQ(count(xmf, "<Grid Name=\"walls\""), 0u);
  const auto times = time_values(xmf);
  ASSERT_EQ(times.size(), 2u);
  EXPECT_EQ(std::strtod(times[0].c_str(), nullptr), t0);
  EXPECT_EQ(std::strtod(times[1].c_str(), nullptr), t1);
  for (const auto& v : attribute_values(xmf, "NumberOfElements")) EXPECT_EQ(v, "5");
  std::size_t references = 0;
  for (std::size_t i = 0; (i = xmf.find("snapshots.h5:", i)) != std::string::npos; ++references) {
    i += 13;
    const std::string path = xmf.substr(i, xmf.find('<', i) - i);
    EXPECT_GT(H5Lexists(file.id, path.c_str(), H5P_DEFAULT), 0) << path;
  }
  // Per snapshot: the topology and every dataset (position as the geometry); then damage.
  const std::size_t datasets = snapshot_datasets(ParticleStore{}).size();
  EXPECT_EQ(references, 2u * (1u + datasets) + 1u);
  EXPECT_EQ(count(xmf, "<Attribute Name=\"angle\" AttributeType=\"Scalar\""), 2u);
  EXPECT_EQ(count(xmf, "<Attribute Name=\"velocity\" AttributeType=\"Vector\""), 2u);
  EXPECT_EQ(count(xmf, "Name=\"damage\""), 1u);
  // The Polyvertex connectivity, shared by both snapshots of 5 particles.
  const auto vertices =
      read_dataset<std::int64_t>(file.id, "/xdmf/polyvertex_5", H5T_NATIVE_INT64, dims);
  EXPECT_EQ(vertices, (std::vector<std::int64_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(count(xmf, "snapshots.h5:/xdmf/polyvertex_5<"), 2u);
}

TEST(SnapshotWriter, OneRankOwnsEverything) {
  // All particles on the last rank: with 2+ ranks, rank 0 owns none.
  ScratchDir dir;
  const int n = 4;
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    ParticleStore a;
    fill(a, n, 2, [](int) { return comm_size() - 1; });
    writer.write(a, 1.0, 7);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  check_snapshot(file.id, "000000", n, 2, 1.0, 7);
}

TEST(SnapshotWriter, NoParticlesAnywhere) {
  ScratchDir dir;
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    ParticleStore empty;
    writer.write(empty, 0.0, 0);
    writer.write(empty, 0.5, 50);
    writer.close();
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  check_snapshot(file.id, "000000", 0, 0, 0.0, 0);
  check_snapshot(file.id, "000001", 0, 0, 0.5, 50);
  const std::string xmf = read_text(dir / "snapshots.xmf");
  EXPECT_EQ(xml_problem(xmf), "");
  EXPECT_EQ(count(xmf, "GridType=\"Uniform\""), 2u);
}

TEST(SnapshotWriter, EmptyMaterialTable) {
  ScratchDir dir;
  { SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), {}); }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  EXPECT_TRUE(read_strings(file.id, "/materials/name").empty());
  EXPECT_GT(H5Lexists(file.id, "/snapshots", H5P_DEFAULT), 0);
  EXPECT_FALSE(fs::exists(dir / "snapshots.xmf"));  // nothing to show yet
}

TEST(SnapshotWriter, StaleSidecarIsRemoved) {
  ScratchDir dir;
  if (comm_rank() == 0) std::ofstream(dir / "snapshots.xmf") << "old";
  MPI_Barrier(MPI_COMM_WORLD);
  { SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials()); }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() == 0) {
    EXPECT_FALSE(fs::exists(dir / "snapshots.xmf"));
  }
}

// The field registry decides what a snapshot holds: every field marked `snapshot` (and no
// other) is a dataset of its name, type and shape, with its unit and description attached.
TEST(SnapshotWriter, EveryRegistryFieldMarkedForOutputIsWrittenWithItsUnit) {
  ScratchDir dir;
  const int n = 6;
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    ParticleStore p;
    fill(p, n, 3, [&](int k) { return block_owner(k, n); });
    writer.write(p, 0.5, 50);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  const ParticleStore registry;
  std::set<std::string> marked;
  for (const FieldBase* f : registry.fields()) {
    if (!f->meta().snapshot) continue;
    marked.insert(f->name());
    SCOPED_TRACE("field " + f->name());
    EXPECT_FALSE(f->meta().unit.empty());
    EXPECT_FALSE(f->meta().doc.empty());
    const std::string path = "/snapshots/000000/" + f->name();
    ASSERT_GT(H5Lexists(file.id, path.c_str(), H5P_DEFAULT), 0);
    EXPECT_EQ(read_string_attribute(file.id, path, "unit"), f->meta().unit);
    EXPECT_EQ(read_string_attribute(file.id, path, "doc"), f->meta().doc);
    H5Closer d{H5Dopen2(file.id, path.c_str(), H5P_DEFAULT), H5Dclose};
    H5Closer space{H5Dget_space(d.id), H5Sclose};
    Dims dims(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space.id)));
    H5Sget_simple_extent_dims(space.id, dims.data(), nullptr);
    EXPECT_EQ(dims[0], static_cast<hsize_t>(n));
    EXPECT_EQ(H5Dget_storage_size(d.id) / static_cast<hsize_t>(n), f->bytes_per_item())
        << "one item of the field per row";
  }
  EXPECT_TRUE(marked.contains("angle")) << "the rotation angle is state a user reads back";
  EXPECT_FALSE(marked.contains("force")) << "accumulators are not state";
  std::set<std::string> datasets = marked;
  datasets.insert("speed");  // derived, after the registry's
  EXPECT_EQ(group_members(file.id, "/snapshots/000000"), datasets) << "nothing else is written";
  // snapshot_datasets() describes the same datasets, in registry order.
  std::set<std::string> described;
  for (const SnapshotDataset& d : snapshot_datasets(registry)) described.insert(d.name);
  EXPECT_EQ(described, datasets);
}

// docs/output.md's table of snapshot datasets is the registry's, row for row, with the fields
// a scene with shaped particles adds (run the test to see the rows to paste when a field
// changes).
TEST(SnapshotWriter, OutputDocsListExactlyTheRegistryDatasets) {
  if (comm_rank() != 0) return;
  const std::string docs = read_text(std::string(DEM2D_SOURCE_DIR) + "/docs/output.md");
  const std::size_t begin = docs.find("\n## snapshots.h5\n");
  ASSERT_NE(begin, std::string::npos);
  const std::size_t end = docs.find("\n## ", begin + 1);
  std::set<std::string> documented;
  std::istringstream section(docs.substr(begin, end - begin));
  for (std::string line; std::getline(section, line);)
    if (line.starts_with("| `")) documented.insert(line);
  std::set<std::string> expected_rows;
  std::string table;
  ParticleStore shaped;
  shaped.enable_shape();
  for (const SnapshotDataset& d : snapshot_datasets(shaped)) {
    const std::string shape = d.columns == 1 ? "(N)" : "(N, " + std::to_string(d.columns) + ")";
    const std::string row =
        "| `" + d.name + "` | " + d.type + " | " + shape + " | " + d.unit + " | " + d.doc + " |";
    expected_rows.insert(row);
    table += row + "\n";
  }
  EXPECT_EQ(documented, expected_rows) << "the rows docs/output.md should have:\n" << table;
}

TEST(SnapshotWriter, ExtraFieldMayNotReuseARegistryName) {
  ScratchDir dir;
  SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
  ParticleStore p;
  const std::vector<double> values = fill(p, 3, 0, [](int) { return 0; });
  const ExtraField clash[] = {{"angle", values}};
  EXPECT_THROW(writer.write(p, 0.0, 0, {}, clash), std::invalid_argument);
  const std::vector<double> zeros(values.size(), 0.0);
  const ExtraField derived[] = {{"speed", zeros}};
  EXPECT_THROW(writer.write(p, 0.0, 0, {}, derived), std::invalid_argument);
}

void expect_same_io_error_everywhere(const std::function<void()>& f, const std::string& prefix) {
  std::string message;
  try {
    f();
    ADD_FAILURE() << "no IoError";
  } catch (const IoError& e) {
    message = e.what();
  }
  EXPECT_EQ(message.rfind(prefix, 0), 0u) << "message: " << message;
  if (prefix.ends_with(": ")) {
    EXPECT_GT(message.size(), prefix.size()) << "no reason given";
  }
  if (std::getenv("DEM2D_SHOW_ERRORS") != nullptr && comm_rank() == 0) {
    std::printf("[ message  ] %s\n", message.c_str());
  }
  EXPECT_EQ(message, rank0_string(message)) << "ranks disagree";
}

TEST(SnapshotWriter, UnwritableDirectoryFailsOnEveryRank) {
  ScratchDir dir;
  if (comm_rank() == 0) std::ofstream(dir / "plain_file") << "x";
  MPI_Barrier(MPI_COMM_WORLD);
  const std::string as_dir = dir / "plain_file";
  expect_same_io_error_everywhere(
      [&] { SnapshotWriter w(MPI_COMM_WORLD, as_dir, test_materials()); },
      "cannot create " + as_dir + "/snapshots.h5: ");
  const std::string missing = dir / "no/such/dir";
  expect_same_io_error_everywhere(
      [&] { SnapshotWriter w(MPI_COMM_WORLD, missing, test_materials()); },
      "cannot create " + missing + "/snapshots.h5: No such file or directory");
}

// --- complete or absent snapshots, the sidecar appended in place, resume ------------------

const std::string kXdmfTrailer = "    </Grid>\n  </Domain>\n</Xdmf>\n";

// A wall outline for snapshot `version`: a closed square turned by the version (4 points, 4
// segments) and an open 3-point polyline (3 points, 2 segments), values not round in binary.
std::vector<std::vector<Vec2>> outline(int version) {
  const double a = 0.1 * version + 1.0 / 3.0;
  const Vec2 c{std::cos(a), std::sin(a)};
  const std::vector<Vec2> square{c, {-c.y, c.x}, {-c.x, -c.y}, {c.y, -c.x}, c};
  const std::vector<Vec2> open{{0.1, -1.0 / 7.0}, {0.2, -0.5 + version}, {0.3, -1.0 / 7.0}};
  return {square, open};
}

// Writes particles [0, n) of `version`, in blocks over the ranks, at `time` (step 1000 x
// version), with the extra field `damage` and the outline(version) when asked.
void write_version(SnapshotWriter& w, int n, int version, double time, bool with_damage = false,
                   bool with_walls = false) {
  ParticleStore p;
  const std::vector<double> dmg = fill(p, n, version, [n](int k) { return block_owner(k, n); });
  const ExtraField extra[] = {{"damage", dmg}};
  const auto walls = with_walls ? outline(version) : std::vector<std::vector<Vec2>>{};
  w.write(p, time, 1000 * version, walls,
          with_damage ? std::span<const ExtraField>(extra) : std::span<const ExtraField>());
}

std::uint64_t inode(const std::string& path) {
  struct stat s {};
  return ::stat(path.c_str(), &s) == 0 ? static_cast<std::uint64_t>(s.st_ino) : 0;
}

// The `Time Value`s of a sidecar, as numbers.
std::vector<double> xdmf_times(const std::string& xmf) {
  std::vector<double> out;
  for (const std::string& v : time_values(xmf)) out.push_back(std::strtod(v.c_str(), nullptr));
  return out;
}

// A write that fails part-way (as on a full disk; fail_before_dataset_for_testing stands in for
// the disk) leaves its partial group under /incomplete, never under /snapshots, and the sidecar
// lists only the complete snapshots. Failing before the first dataset, in the middle, and after
// the last (before the flush and the move).
TEST(SnapshotWriter, FailedWriteLeavesOnlyCompleteSnapshots) {
  const std::size_t datasets = snapshot_datasets(ParticleStore{}).size();
  for (const std::size_t k : {std::size_t{0}, std::size_t{3}, datasets}) {
    SCOPED_TRACE("failing before dataset " + std::to_string(k));
    ScratchDir dir;
    const int n = 5;
    {
      SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
      write_version(writer, n, 0, 0.1);
      writer.fail_before_dataset_for_testing(k);
      expect_same_io_error_everywhere([&] { write_version(writer, n + 2, 1, 0.2); },
                                      dir / "snapshots.h5" + ": cannot ");
      EXPECT_EQ(writer.snapshots_written(), 1u);
      writer.close();
    }
    MPI_Barrier(MPI_COMM_WORLD);
    if (comm_rank() != 0) continue;
    H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
    ASSERT_GE(file.id, 0);
    EXPECT_EQ(group_members(file.id, "/snapshots"), (std::set<std::string>{"000000"}));
    check_snapshot(file.id, "000000", n, 0, 0.1, 0);
    // The partial group: outside /snapshots, with the datasets written before the failure.
    EXPECT_EQ(group_members(file.id, "/incomplete"), (std::set<std::string>{"000001"}));
    EXPECT_EQ(group_members(file.id, "/incomplete/000001").size(), k);
    const std::string xmf = read_text(dir / "snapshots.xmf");
    EXPECT_EQ(xml_problem(xmf), "");
    EXPECT_EQ(count(xmf, "GridType=\"Uniform\""), 1u);
    EXPECT_EQ(count(xmf, "/000001"), 0u);
  }
}

// After a failed write the writer goes on: the next write removes the remains (the staging
// group, a connectivity dataset written for it) and takes the failed snapshot's number.
TEST(SnapshotWriter, AWriteAfterAFailedOneTakesItsNumber) {
  ScratchDir dir;
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    write_version(writer, 5, 0, 0.1);
    // Every dataset and /xdmf/polyvertex_7 written, then the flush fails.
    writer.fail_before_dataset_for_testing(snapshot_datasets(ParticleStore{}).size());
    EXPECT_THROW(write_version(writer, 7, 1, 0.2), IoError);
    write_version(writer, 7, 2, 0.3, true);
    ASSERT_EQ(writer.snapshots_written(), 2u);
    EXPECT_EQ(writer.last_snapshot()->name, "000001");
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  EXPECT_EQ(group_members(file.id, "/snapshots"), (std::set<std::string>{"000000", "000001"}));
  check_snapshot(file.id, "000000", 5, 0, 0.1, 0);
  check_snapshot(file.id, "000001", 7, 2, 0.3, 2000);
  EXPECT_GT(H5Lexists(file.id, "/snapshots/000001/damage", H5P_DEFAULT), 0);
  EXPECT_TRUE(group_members(file.id, "/incomplete").empty());
  Dims dims;
  EXPECT_EQ(read_dataset<std::int64_t>(file.id, "/xdmf/polyvertex_7", H5T_NATIVE_INT64, dims),
            (std::vector<std::int64_t>{0, 1, 2, 3, 4, 5, 6}));
  const std::string xmf = read_text(dir / "snapshots.xmf");
  EXPECT_EQ(xml_problem(xmf), "");
  EXPECT_EQ(xdmf_times(xmf), (std::vector<double>{0.1, 0.3}));
}

// /walls/NAME against outline(version): the square's 4 points (closed: its last segment back
// to its first point), the open polyline's 3; time and step as the snapshot's.
void check_outline(hid_t file, const std::string& name, int version, double time,
                   std::int64_t step) {
  SCOPED_TRACE("outline " + name);
  const std::string g = "/walls/" + name;
  EXPECT_EQ(read_attribute<double>(file, g, "time", H5T_NATIVE_DOUBLE), time);
  EXPECT_EQ(read_attribute<std::int64_t>(file, g, "step", H5T_NATIVE_INT64), step);
  EXPECT_EQ(read_string_attribute(file, g + "/points", "unit"), "m");
  Dims dims;
  const auto points = read_dataset<double>(file, g + "/points", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (Dims{7, 2}));
  std::vector<double> expected;
  const auto lines = outline(version);
  for (std::size_t k = 0; k < 4; ++k)
    expected.insert(expected.end(), {lines[0][k].x, lines[0][k].y});
  for (const Vec2 q : lines[1]) expected.insert(expected.end(), {q.x, q.y});
  EXPECT_EQ(points, expected);
  const auto segments = read_dataset<std::int64_t>(file, g + "/segments", H5T_NATIVE_INT64, dims);
  EXPECT_EQ(dims, (Dims{6, 2}));
  EXPECT_EQ(segments, (std::vector<std::int64_t>{0, 1, 1, 2, 2, 3, 3, 0, 4, 5, 5, 6}));
}

// The HDF5 object a path names (its address): two paths of one object name one stored dataset.
haddr_t object_address(hid_t file, const std::string& path) {
  H5O_info_t info{};
  EXPECT_GE(H5Oget_info_by_name(file, path.c_str(), &info, H5P_DEFAULT), 0) << path;
  return info.addr;
}

// What a snapshot stores: the stable fields (id, material, radius) and the outline's segments
// once while they do not change, each later snapshot naming the stored dataset (a hard link);
// the other fields every time, even when equal; the outline's points again when they move;
// the stable fields again when the particles change. Every snapshot still has every dataset,
// and the sidecar names every one of them.
TEST(SnapshotWriter, StableFieldsAndAStillOutlineAreStoredOnce) {
  ScratchDir dir;
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    write_version(writer, 5, 0, 0.1, false, true);
    write_version(writer, 5, 0, 0.2, false, true);  // the same state: only time and step differ
    write_version(writer, 5, 1, 0.3, false, true);  // moved, the outline turned
    write_version(writer, 6, 1, 0.4, false, true);  // one particle more
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  const auto at = [&](const std::string& name, const std::string& dataset) {
    return object_address(file.id, "/snapshots/" + name + "/" + dataset);
  };
  for (const char* stable : {"id", "material", "radius"}) {
    SCOPED_TRACE(stable);
    EXPECT_EQ(at("000000", stable), at("000001", stable));
    EXPECT_EQ(at("000000", stable), at("000002", stable));
    EXPECT_NE(at("000002", stable), at("000003", stable));
  }
  for (const char* moving : {"position", "velocity", "angle", "spin", "speed"}) {
    SCOPED_TRACE(moving);
    EXPECT_NE(at("000000", moving), at("000001", moving));
  }
  const auto wall = [&](const std::string& name, const std::string& dataset) {
    return object_address(file.id, "/walls/" + name + "/" + dataset);
  };
  EXPECT_EQ(wall("000000", "points"), wall("000001", "points"));
  EXPECT_NE(wall("000001", "points"), wall("000002", "points"));
  for (const char* name : {"000001", "000002", "000003"})
    EXPECT_EQ(wall("000000", "segments"), wall(name, "segments"));
  const double times[] = {0.1, 0.2, 0.3, 0.4};
  for (int v = 0; v < 4; ++v) {  // read back through every name, as any reader does
    const std::string name = "00000" + std::to_string(v);
    check_snapshot(file.id, name, v < 3 ? 5 : 6, v < 2 ? 0 : 1, times[v], v < 2 ? 0 : 1000);
  }
  check_outline(file.id, "000001", 0, 0.2, 0);
  check_outline(file.id, "000003", 1, 0.4, 1000);
  const std::string xmf = read_text(dir / "snapshots.xmf");
  for (const char* d : {"id", "material", "radius", "velocity", "speed"})
    EXPECT_EQ(count(xmf, "/" + std::string(d) + "</DataItem>"), 4u) << d;
  EXPECT_EQ(count(xmf, "/segments</DataItem>"), 4u);
}

// The outline given to write() goes to /walls/NNNNNN (rank 0's), the sidecar draws it as a
// Polyline grid beside the particles; a snapshot without one has neither. Every snapshot names
// the materials: the `names` attribute of its material rows, and the sidecar's Information and
// field data.
TEST(SnapshotWriter, WallOutlineAndMaterialNamesAreWrittenWithTheSnapshot) {
  ScratchDir dir;
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    write_version(writer, 5, 0, 0.1, false, true);
    EXPECT_EQ(writer.last_snapshot()->wall_points, 7u);
    EXPECT_EQ(writer.last_snapshot()->wall_segments, 6u);
    write_version(writer, 4, 1, 0.2);
    EXPECT_EQ(writer.last_snapshot()->wall_segments, 0u);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  check_snapshot(file.id, "000000", 5, 0, 0.1, 0);
  check_snapshot(file.id, "000001", 4, 1, 0.2, 1000);
  EXPECT_EQ(group_members(file.id, "/walls"), (std::set<std::string>{"000000"}));
  EXPECT_EQ(group_members(file.id, "/walls/000000"), (std::set<std::string>{"points", "segments"}));
  check_outline(file.id, "000000", 0, 0.1, 0);
  for (const char* name : {"000000", "000001"})
    EXPECT_EQ(
        read_string_attribute(file.id, std::string("/snapshots/") + name + "/material", "names"),
        "0=steel,1=iron ore,2=rubber-liner");
  const std::string xmf = read_text(dir / "snapshots.xmf");
  EXPECT_EQ(xml_problem(xmf), "");
  EXPECT_EQ(count(xmf,
                  "<Information Name=\"material_names\" "
                  "Value=\"0=steel,1=iron ore,2=rubber-liner\"/>"),
            1u);
  EXPECT_EQ(count(xmf,
                  "<Attribute Name=\"material: rubber-liner\" AttributeType=\"Scalar\" "
                  "Center=\"Grid\">"),
            2u);
  EXPECT_EQ(count(xmf, "Format=\"XML\">2</DataItem>"), 2u);
  EXPECT_EQ(count(xmf, "<Attribute Name=\"speed\" AttributeType=\"Scalar\" Center=\"Node\">"), 2u);
  EXPECT_EQ(count(xmf, "<Grid Name=\"walls\" GridType=\"Uniform\">"), 1u);
  EXPECT_EQ(count(xmf,
                  "<Topology TopologyType=\"Polyline\" NumberOfElements=\"6\" "
                  "NodesPerElement=\"2\">"),
            1u);
  EXPECT_EQ(count(xmf,
                  "Dimensions=\"6 2\" NumberType=\"Int\" Precision=\"8\" "
                  "Format=\"HDF\">snapshots.h5:/walls/000000/segments<"),
            1u);
  EXPECT_EQ(count(xmf,
                  "Dimensions=\"7 2\" NumberType=\"Float\" Precision=\"8\" "
                  "Format=\"HDF\">snapshots.h5:/walls/000000/points<"),
            1u);
  EXPECT_EQ(count(xmf, "/walls/000001"), 0u);
}

// A write that fails after staging its outline leaves it under /incomplete, never under /walls;
// the next write clears it and publishes its own.
TEST(SnapshotWriter, AFailedWritesOutlineStaysStagedAndTheNextWriteReplacesIt) {
  const std::size_t datasets = snapshot_datasets(ParticleStore{}).size();
  {
    ScratchDir stopped;  // the run stops after the failed write
    {
      SnapshotWriter writer(MPI_COMM_WORLD, stopped.path(), test_materials());
      write_version(writer, 5, 0, 0.1, false, true);
      writer.fail_before_dataset_for_testing(datasets);  // after the outline, before the flush
      EXPECT_THROW(write_version(writer, 5, 1, 0.2, false, true), IoError);
      writer.close();
    }
    MPI_Barrier(MPI_COMM_WORLD);
    if (comm_rank() == 0) {
      H5Closer f{H5Fopen((stopped / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT),
                 H5Fclose};
      ASSERT_GE(f.id, 0);
      EXPECT_EQ(group_members(f.id, "/incomplete"),
                (std::set<std::string>{"000001", "walls_000001"}));
      EXPECT_EQ(group_members(f.id, "/walls"), (std::set<std::string>{"000000"}));
      EXPECT_EQ(count(read_text(stopped / "snapshots.xmf"), "/walls/000001"), 0u);
    }
  }
  ScratchDir dir;
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    write_version(writer, 5, 0, 0.1, false, true);
    writer.fail_before_dataset_for_testing(datasets);
    EXPECT_THROW(write_version(writer, 5, 1, 0.2, false, true), IoError);
    write_version(writer, 5, 2, 0.3, false, true);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  EXPECT_TRUE(group_members(file.id, "/incomplete").empty());
  EXPECT_EQ(group_members(file.id, "/walls"), (std::set<std::string>{"000000", "000001"}));
  check_outline(file.id, "000000", 0, 0.1, 0);
  check_outline(file.id, "000001", 2, 0.3, 2000);
}

// Each snapshot appends its grid in place (the same file, the old text less its trailer kept
// as it was), the sidecar is valid after every write, and after five appends it is, byte for
// byte, the sidecar regenerated from the file's groups (resume() keeping them all).
TEST(SnapshotWriter, SidecarIsAppendedInPlaceAndEqualsTheRegeneratedOne) {
  ScratchDir dir;
  const std::string path = dir / "snapshots.xmf";
  const int counts[] = {5, 5, 0, 3, 5};
  std::string appended;
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    std::uint64_t created = 0;
    for (int v = 0; v < 5; ++v) {
      write_version(writer, counts[v], v, 0.1 * (v + 1), v == 3, v == 1 || v >= 3);
      if (comm_rank() != 0) continue;
      SCOPED_TRACE("after snapshot " + std::to_string(v));
      const std::string xmf = read_text(path);
      EXPECT_EQ(xml_problem(xmf), "");
      EXPECT_TRUE(xmf.ends_with(kXdmfTrailer));
      EXPECT_EQ(count(xmf, "<Grid Name=\"particles\""), static_cast<std::size_t>(v + 1));
      if (v == 0) {
        created = inode(path);
      } else {
        EXPECT_EQ(inode(path), created) << "written in place, not replaced";
        EXPECT_TRUE(xmf.starts_with(appended.substr(0, appended.size() - kXdmfTrailer.size())));
      }
      appended = xmf;
    }
  }
  MPI_Barrier(MPI_COMM_WORLD);
  {
    const auto all = SnapshotWriter::resume(MPI_COMM_WORLD, dir.path(), {}, 1e300, 0.0);
    EXPECT_EQ(all->snapshots_written(), 5u);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  const std::string regenerated = read_text(path);
  EXPECT_EQ(regenerated, appended);
  EXPECT_EQ(xdmf_times(regenerated), (std::vector<double>{0.1, 0.2, 0.1 * 3, 0.4, 0.5}));
  EXPECT_EQ(count(regenerated, "Name=\"damage\""), 1u);
  EXPECT_EQ(count(regenerated, "NumberOfElements=\"0\""), 1u);
  EXPECT_EQ(count(regenerated, "<Grid Name=\"walls\""), 3u);
  EXPECT_EQ(count(regenerated, "Name=\"material: iron ore\""), 5u);
}

// A restart from a checkpoint at t = 0.3: the snapshots the interrupted run wrote after it
// (and its half-written one) go, the sidecar lists the kept ones exactly as it did when the
// last of them was written, and the next snapshot continues the numbering.
TEST(SnapshotWriter, ResumeDropsTheSnapshotsAfterTheCheckpointAndContinues) {
  ScratchDir dir;
  std::string at_checkpoint;  // the sidecar just after the checkpoint's snapshot
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    for (int v = 0; v < 5; ++v) {
      write_version(writer, v < 3 ? 5 : 6, v, 0.1 * (v + 1), false, true);
      if (v == 2 && comm_rank() == 0) at_checkpoint = read_text(dir / "snapshots.xmf");
    }
    writer.fail_before_dataset_for_testing(2);  // interrupted: /incomplete/000005 is left
    EXPECT_THROW(write_version(writer, 6, 5, 0.6, false, true), IoError);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  {
    // A hair before 0.1 * 3: the tolerance keeps 000002.
    const auto writer = SnapshotWriter::resume(MPI_COMM_WORLD, dir.path(), {}, 0.3 - 1e-12, 1e-9);
    ASSERT_EQ(writer->snapshots_written(), 3u);
    EXPECT_EQ(writer->last_snapshot()->name, "000002");
    EXPECT_EQ(writer->last_snapshot()->time, 0.1 * 3);
    EXPECT_EQ(writer->last_snapshot()->step, 2000);
    EXPECT_EQ(writer->last_snapshot()->particles, 5u);
    if (comm_rank() == 0) {
      EXPECT_EQ(read_text(dir / "snapshots.xmf"), at_checkpoint);
    }
    EXPECT_EQ(writer->last_snapshot()->wall_points, 7u);
    EXPECT_EQ(writer->last_snapshot()->wall_segments, 6u);
    write_version(*writer, 5, 9, 0.35, false, true);
    EXPECT_EQ(writer->last_snapshot()->name, "000003");
    writer->close();
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  EXPECT_EQ(group_members(file.id, "/snapshots"),
            (std::set<std::string>{"000000", "000001", "000002", "000003"}));
  for (int v = 0; v < 3; ++v)
    check_snapshot(file.id, "00000" + std::to_string(v), 5, v, 0.1 * (v + 1), 1000 * v);
  check_snapshot(file.id, "000003", 5, 9, 0.35, 9000);
  EXPECT_TRUE(group_members(file.id, "/incomplete").empty());
  // The dropped snapshots' outlines are gone with them.
  EXPECT_EQ(group_members(file.id, "/walls"),
            (std::set<std::string>{"000000", "000001", "000002", "000003"}));
  check_outline(file.id, "000002", 2, 0.1 * 3, 2000);
  check_outline(file.id, "000003", 9, 0.35, 9000);
  // The dropped snapshots' connectivity is gone with them.
  EXPECT_EQ(group_members(file.id, "/xdmf"), (std::set<std::string>{"polyvertex_5"}));
  const std::string xmf = read_text(dir / "snapshots.xmf");
  EXPECT_EQ(xml_problem(xmf), "");
  EXPECT_TRUE(xmf.starts_with(at_checkpoint.substr(0, at_checkpoint.size() - kXdmfTrailer.size())));
  EXPECT_EQ(xdmf_times(xmf), (std::vector<double>{0.1, 0.2, 0.1 * 3, 0.35}));
  EXPECT_EQ(count(xmf, "polyvertex_6"), 0u);
}

TEST(SnapshotWriter, ResumeWithoutAFileCreatesIt) {
  ScratchDir dir;
  {
    const auto writer =
        SnapshotWriter::resume(MPI_COMM_WORLD, dir.path(), test_materials(), 1.0, 1e-9);
    EXPECT_EQ(writer->snapshots_written(), 0u);
    write_version(*writer, 4, 0, 1.5);
    EXPECT_EQ(writer->last_snapshot()->name, "000000");
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  EXPECT_EQ(read_strings(file.id, "/materials/name"),
            (std::vector<std::string>{"steel", "iron ore", "rubber-liner"}));
  check_snapshot(file.id, "000000", 4, 0, 1.5, 0);
  EXPECT_EQ(xdmf_times(read_text(dir / "snapshots.xmf")), (std::vector<double>{1.5}));
}

TEST(SnapshotWriter, ResumeOfAFileThatIsNotASnapshotFileFailsOnEveryRank) {
  ScratchDir dir;
  const std::string h5 = dir / "snapshots.h5";
  if (comm_rank() == 0) std::ofstream(h5) << "not an HDF5 file";
  MPI_Barrier(MPI_COMM_WORLD);
  const auto resume = [&] { SnapshotWriter::resume(MPI_COMM_WORLD, dir.path(), {}, 1.0, 0.0); };
  expect_same_io_error_everywhere(resume, "cannot open " + h5 + ": ");
  {
    auto f = h5::ParallelFile::create(MPI_COMM_WORLD, h5);  // HDF5, but no /snapshots
    f.create_group("/other");
    f.close();
  }
  expect_same_io_error_everywhere(resume, h5 + ": cannot resume: no /snapshots group");
}

// A sidecar that cannot be written is an IoError; the snapshot is in snapshots.h5 all the same,
// and the next write makes the sidecar anew, listing it.
TEST(SnapshotWriter, SidecarFailureIsReportedAndTheNextWriteRewritesIt) {
  ScratchDir dir;
  const std::string xmf = dir / "snapshots.xmf";
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    write_version(writer, 3, 0, 0.1);
    if (comm_rank() == 0) {
      fs::remove(xmf);
      fs::create_directory(xmf);  // neither opened nor replaced by a rename
    }
    MPI_Barrier(MPI_COMM_WORLD);
    expect_same_io_error_everywhere([&] { write_version(writer, 3, 1, 0.2); },
                                    "cannot rename " + xmf + ".tmp to " + xmf + ": ");
    EXPECT_EQ(writer.snapshots_written(), 2u);
    if (comm_rank() == 0) {
      EXPECT_FALSE(fs::exists(xmf + ".tmp"));
      fs::remove(xmf);
    }
    MPI_Barrier(MPI_COMM_WORLD);
    write_version(writer, 3, 2, 0.3);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  const std::string text = read_text(xmf);
  EXPECT_EQ(xml_problem(text), "");
  EXPECT_EQ(xdmf_times(text), (std::vector<double>{0.1, 0.2, 0.3}));
}

// snapshots.xmf checked against snapshots.h5 by tests/io/check_xdmf.py (python3 with
// xml.etree and h5py): every DataItem names a dataset of the file with the stated Dimensions,
// NumberType and Precision; topologies, geometries and attributes agree in size; the grids are
// exactly the file's snapshots and outlines; the material names are the file's. Checked after
// appends (with and without an outline, no particles, an extra field), and after a resume
// regenerated the sidecar and appended to it.
TEST(XdmfSidecar, EveryDataItemMatchesTheHdf5File) {
  ScratchDir dir;
  const auto check = [&](const std::string& when) {
    MPI_Barrier(MPI_COMM_WORLD);
    if (comm_rank() != 0) return;
    const std::string log = dir / "check_xdmf.log";
    const std::string command = "/usr/bin/python3 '" + std::string(DEM2D_SOURCE_DIR) +
                                "/tests/io/check_xdmf.py' '" + (dir / "snapshots.xmf") + "' > '" +
                                log + "' 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0) << when << ":\n" << read_text(log);
  };
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    write_version(writer, 5, 0, 0.1, false, true);
    write_version(writer, 0, 1, 0.2, false, true);
    write_version(writer, 6, 2, 0.3, true, false);
    write_version(writer, 6, 3, 0.4, true, true);
  }
  check("after four snapshots");
  {
    const auto writer = SnapshotWriter::resume(MPI_COMM_WORLD, dir.path(), {}, 0.35, 1e-9);
    write_version(*writer, 7, 4, 0.5, false, true);
  }
  check("after a resume and one more snapshot");
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), {});  // no materials
    write_version(writer, 3, 0, 0.0, false, true);
  }
  check("without materials");
}

// --- The shell's finite elements --------------------------------------------------------------

// A shell of two 9-node elements side by side on a 5 x 3 grid of nodes (node (i, j): 5 j + i),
// the ring's and bar 0's, its fields a function of `version`.
struct TestShell {
  std::vector<Vec2> position, displacement;
  std::vector<double> von_mises;
  std::vector<std::array<int, 9>> elements;
  std::vector<int> element_bar{-1, 0};
  ShellSnapshot view() const { return {position, displacement, von_mises, elements, element_bar}; }
};

TestShell test_shell(int version) {
  TestShell s;
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 5; ++i) {
      s.position.push_back({0.01 * i + version, 0.01 * j});
      s.displacement.push_back({1e-7 * (i + 1) * (version + 1), -1e-7 * j});
      s.von_mises.push_back(1e6 * (i + j + version) + 1.0 / 3.0);
    }
  }
  const auto n = [](int i, int j) { return 5 * j + i; };
  for (const int i : {0, 2})
    s.elements.push_back({n(i, 0), n(i + 2, 0), n(i + 2, 2), n(i, 2), n(i + 1, 0), n(i + 2, 1),
                          n(i + 1, 2), n(i, 1), n(i + 1, 1)});
  return s;
}

// Writes particles [0, 5) of `version` with its wall outline and test_shell(version), which rank
// 0 alone passes.
void write_shell_version(SnapshotWriter& w, int version, double time) {
  ParticleStore p;
  fill(p, 5, version, [](int k) { return block_owner(k, 5); });
  const TestShell shell = test_shell(version);
  const ShellSnapshot view = shell.view();
  w.write(p, time, 1000 * version, outline(version), {}, comm_rank() == 0 ? &view : nullptr);
}

// The shell is rank 0's, written with its snapshot (the mesh once per file); a resume keeps the
// shell of the kept snapshots only; a file without a shell has no shell groups.
TEST(SnapshotWriter, TheShellIsRankZerosAndAResumeTrimsItWithItsSnapshot) {
  ScratchDir dir;
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    write_version(writer, 5, 0, 0.1, false, true);  // no shell
    for (int v = 1; v < 4; ++v) write_shell_version(writer, v, 0.1 * (v + 1));
  }
  MPI_Barrier(MPI_COMM_WORLD);
  {
    const auto writer = SnapshotWriter::resume(MPI_COMM_WORLD, dir.path(), {}, 0.25, 1e-9);
    ASSERT_EQ(writer->snapshots_written(), 2u);
    EXPECT_EQ(writer->last_snapshot()->shell_nodes, 15u);
    EXPECT_EQ(writer->last_snapshot()->shell_elements, 2u);
    write_shell_version(*writer, 5, 0.5);
    writer->close();
  }
  MPI_Barrier(MPI_COMM_WORLD);
  ScratchDir bare;
  {
    SnapshotWriter writer(MPI_COMM_WORLD, bare.path(), test_materials());
    write_version(writer, 5, 0, 0.1, false, true);
    writer.close();
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  {
    H5Closer file{H5Fopen((bare / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
    ASSERT_GE(file.id, 0);
    const std::set<std::string> top = group_members(file.id, "/");
    EXPECT_FALSE(top.contains("shell") || top.contains("shell_mesh"));
    EXPECT_EQ(count(read_text(bare / "snapshots.xmf"), "Name=\"shell\""), 0u);
  }
  H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  EXPECT_EQ(group_members(file.id, "/snapshots"),
            (std::set<std::string>{"000000", "000001", "000002"}));
  EXPECT_EQ(group_members(file.id, "/shell"), (std::set<std::string>{"000001", "000002"}));
  EXPECT_TRUE(group_members(file.id, "/incomplete").empty());
  const std::pair<std::string, int> kept[] = {{"000001", 1}, {"000002", 5}};
  for (const auto& [name, version] : kept) {
    const TestShell want = test_shell(version);
    const std::string g = "/shell/" + name;
    EXPECT_EQ(read_attribute<std::int64_t>(file.id, g, "step", H5T_NATIVE_INT64), 1000 * version);
    Dims dims;
    const auto points = read_dataset<double>(file.id, g + "/points", H5T_NATIVE_DOUBLE, dims);
    EXPECT_EQ(dims, (Dims{15, 2}));
    const auto moved = read_dataset<double>(file.id, g + "/displacement", H5T_NATIVE_DOUBLE, dims);
    EXPECT_EQ(dims, (Dims{15, 2}));
    const auto vm = read_dataset<double>(file.id, g + "/von_mises", H5T_NATIVE_DOUBLE, dims);
    EXPECT_EQ(dims, (Dims{15}));
    ASSERT_EQ(points.size(), 30u);
    ASSERT_EQ(moved.size(), 30u);
    ASSERT_EQ(vm.size(), 15u);
    for (std::size_t k = 0; k < 15; ++k) {
      EXPECT_EQ(points[2 * k], want.position[k].x);
      EXPECT_EQ(points[2 * k + 1], want.position[k].y);
      EXPECT_EQ(moved[2 * k], want.displacement[k].x);
      EXPECT_EQ(moved[2 * k + 1], want.displacement[k].y);
      EXPECT_EQ(vm[k], want.von_mises[k]);
    }
    EXPECT_EQ(read_string_attribute(file.id, g + "/von_mises", "unit"), "Pa");
  }
  Dims dims;
  const auto elements =
      read_dataset<std::int64_t>(file.id, "/shell_mesh/elements", H5T_NATIVE_INT64, dims);
  EXPECT_EQ(dims, (Dims{2, 9}));
  EXPECT_EQ(elements, (std::vector<std::int64_t>{0, 2, 12, 10, 1, 7, 11, 5, 6,  //
                                                 2, 4, 14, 12, 3, 9, 13, 7, 8}));
  EXPECT_EQ(read_dataset<std::int64_t>(file.id, "/shell_mesh/element_bar", H5T_NATIVE_INT64, dims),
            (std::vector<std::int64_t>{-1, 0}));
  // The quarters of an element: the four cells of its 3 x 3 nodes, counter-clockwise.
  const auto quads =
      read_dataset<std::int64_t>(file.id, "/shell_mesh/quadrilaterals", H5T_NATIVE_INT64, dims);
  EXPECT_EQ(dims, (Dims{8, 4}));
  EXPECT_EQ(quads, (std::vector<std::int64_t>{0, 1, 6, 5, 1, 2, 7, 6, 6, 7, 12, 11, 5, 6, 11, 10,
                                              2, 3, 8, 7, 3, 4, 9, 8, 8, 9, 14, 13, 7, 8, 13, 12}));
  EXPECT_EQ(
      read_dataset<std::int64_t>(file.id, "/shell_mesh/quadrilateral_bar", H5T_NATIVE_INT64, dims),
      (std::vector<std::int64_t>{-1, -1, -1, -1, 0, 0, 0, 0}));
  const std::string xmf = read_text(dir / "snapshots.xmf");
  EXPECT_EQ(xml_problem(xmf), "");
  EXPECT_EQ(count(xmf, "Name=\"shell\""), 2u);
  const std::string log = dir / "check_xdmf.log";
  const std::string command = "/usr/bin/python3 '" + std::string(DEM2D_SOURCE_DIR) +
                              "/tests/io/check_xdmf.py' '" + (dir / "snapshots.xmf") + "' > '" +
                              log + "' 2>&1";
  EXPECT_EQ(std::system(command.c_str()), 0) << read_text(log);
}

// A write that fails after staging its shell (and the file's mesh) leaves nothing published; the
// next write takes its number and writes both afresh.
TEST(SnapshotWriter, AFailedWriteWithAShellIsReplacedByTheNext) {
  ScratchDir dir;
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    writer.fail_before_dataset_for_testing(100);  // after every dataset, before the moves
    EXPECT_THROW(write_shell_version(writer, 1, 0.1), IoError);
    write_shell_version(writer, 2, 0.2);
    EXPECT_EQ(writer.last_snapshot()->name, "000000");
    EXPECT_EQ(writer.last_snapshot()->shell_nodes, 15u);
    writer.close();
  }
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  ASSERT_GE(file.id, 0);
  EXPECT_EQ(group_members(file.id, "/shell"), (std::set<std::string>{"000000"}));
  EXPECT_TRUE(group_members(file.id, "/incomplete").empty());
  EXPECT_EQ(read_attribute<std::int64_t>(file.id, "/shell/000000", "step", H5T_NATIVE_INT64), 2000);
  Dims dims;
  const auto vm = read_dataset<double>(file.id, "/shell/000000/von_mises", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(vm, test_shell(2).von_mises);
  read_dataset<std::int64_t>(file.id, "/shell_mesh/quadrilaterals", H5T_NATIVE_INT64, dims);
  EXPECT_EQ(dims, (Dims{8, 4}));
}

// --- Shaped particles ---------------------------------------------------------------------

// Global particle k of a mixed scene at snapshot `version`: every third a disc, the others
// ellipses and rounded boxes (exponents 2, 4, 12, 50), each turned by its own angle.
struct ShapedExpected {
  std::int64_t id;
  Vec2 pos;
  double a, b, n, angle;
  bool disc;
};

ShapedExpected shaped_expected(int k, int version) {
  const double v = version;
  const bool disc = k % 3 == 0;
  const double exponents[] = {2.0, 4.0, 12.0, 50.0};
  const double a = 0.01 * (k + 2), b = disc ? a : 0.004 * (k + 1);
  return {500 + 3 * k,
          {0.05 * k - 0.2 + v / 9.0, 0.03 * k + v / 7.0},
          a,
          b,
          disc ? 2.0 : exponents[k % 4],
          disc ? 0.1 * v : 0.4 * k - 1.3 + v / 3.0,
          disc};
}

// This rank's particles (contiguous blocks) of the mixed scene at `version` in a shaped store.
void fill_shaped(ParticleStore& store, int n, int version) {
  store.enable_shape();
  for (int k = 0; k < n; ++k) {
    if (block_owner(k, n) != comm_rank()) continue;
    const ShapedExpected e = shaped_expected(k, version);
    if (e.disc) {
      const std::size_t i = store.add(e.id, 0, e.a, 7800.0, e.pos, {0.5, -0.25 * k}, 1.0);
      store.theta[i] = e.angle;
    } else {
      store.add_shaped(e.id, 1, e.a, e.b, e.n, 7800.0, e.pos, {0.5, -0.25 * k}, 1.0, e.angle);
    }
  }
  const std::size_t g = store.add_ghosts(1);  // a ghost: never written
  store.id[g] = -1;
  store.pos[g] = {1e9, 1e9};
}

void write_shaped(SnapshotWriter& w, int n, int version, double time) {
  ParticleStore p;
  fill_shaped(p, n, version);
  w.write(p, time, 100 * version);
}

// The area of the polygon of `k` points starting at row `first` of `xy` (x, y, x, y, ...).
double polygon_area(const std::vector<float>& xy, std::size_t first, std::size_t k) {
  double twice = 0.0;
  for (std::size_t j = 0; j < k; ++j) {
    const std::size_t p = 2 * (first + j), q = 2 * (first + (j + 1) % k);
    twice += static_cast<double>(xy[p]) * xy[q + 1] - static_cast<double>(xy[q]) * xy[p + 1];
  }
  return 0.5 * twice;
}

// Checks /snapshots/NAME and /outlines/NAME against the mixed scene at `version`: the shape
// datasets (discs a = b = r, n = 2) with their units; the outline's points, 24 per particle in
// row order, each the float of superellipse_outline's point; each polygon counter-clockwise
// with the superellipse's area less at most 1.5 %; the connectivity the outlines' grid uses.
void check_shaped_snapshot(hid_t file, const std::string& name, int n, int version) {
  SCOPED_TRACE("snapshot " + name);
  const std::string g = "/snapshots/" + name;
  const auto un = static_cast<hsize_t>(n);
  Dims dims;
  const auto a = read_dataset<double>(file, g + "/semi_axis_a", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(dims, (Dims{un}));
  const auto b = read_dataset<double>(file, g + "/semi_axis_b", H5T_NATIVE_DOUBLE, dims);
  const auto ex = read_dataset<double>(file, g + "/exponent", H5T_NATIVE_DOUBLE, dims);
  const auto angle = read_dataset<double>(file, g + "/angle", H5T_NATIVE_DOUBLE, dims);
  const auto radius = read_dataset<double>(file, g + "/radius", H5T_NATIVE_DOUBLE, dims);
  EXPECT_EQ(read_string_attribute(file, g + "/semi_axis_a", "unit"), "m");
  EXPECT_EQ(read_string_attribute(file, g + "/semi_axis_b", "unit"), "m");
  EXPECT_EQ(read_string_attribute(file, g + "/exponent", "unit"), "1");
  const std::string o = "/outlines/" + name + "/points";
  const auto xy = read_dataset<float>(file, o, H5T_NATIVE_FLOAT, dims);
  const std::size_t k = 24;
  EXPECT_EQ(dims, (Dims{un * k, 2}));
  EXPECT_EQ(read_string_attribute(file, o, "unit"), "m");
  {
    H5Closer d{H5Dopen2(file, o.c_str(), H5P_DEFAULT), H5Dclose};
    H5Closer t{H5Dget_type(d.id), H5Tclose};
    EXPECT_TRUE(H5Tequal(t.id, H5T_IEEE_F32LE) > 0) << "little-endian floats";
  }
  const auto cells = read_dataset<std::int64_t>(file, "/xdmf/polygon_24_" + std::to_string(n),
                                                H5T_NATIVE_INT64, dims);
  EXPECT_EQ(dims, (Dims{un, k}));
  ASSERT_EQ(a.size(), un);
  ASSERT_EQ(xy.size(), 2 * k * un);
  ASSERT_EQ(cells.size(), k * un);
  for (std::size_t i = 0; i < cells.size(); ++i) EXPECT_EQ(cells[i], static_cast<std::int64_t>(i));
  std::vector<Vec2> polygon(k);
  for (int kk = 0; kk < n; ++kk) {
    const auto i = static_cast<std::size_t>(kk);
    const ShapedExpected e = shaped_expected(kk, version);
    EXPECT_EQ(a[i], e.a) << "k=" << kk;
    EXPECT_EQ(b[i], e.b) << "k=" << kk;
    EXPECT_EQ(ex[i], e.n) << "k=" << kk;
    EXPECT_EQ(angle[i], e.angle) << "k=" << kk;
    if (e.disc) {
      EXPECT_EQ(radius[i], e.a) << "k=" << kk;
    }
    const SuperEllipse s{e.a, e.b, e.n};
    superellipse_outline(s, e.pos, e.angle, polygon);
    for (std::size_t j = 0; j < k; ++j) {
      EXPECT_EQ(xy[2 * (i * k + j)], static_cast<float>(polygon[j].x)) << "k=" << kk;
      EXPECT_EQ(xy[2 * (i * k + j) + 1], static_cast<float>(polygon[j].y)) << "k=" << kk;
    }
    const double ratio = polygon_area(xy, i * k, k) / area(s);
    EXPECT_GT(ratio, 0.985) << "k=" << kk << " n=" << e.n;
    EXPECT_LE(ratio, 1.0) << "k=" << kk << " n=" << e.n;
    if (e.n == 2.0) {  // an affine image of the regular 24-gon
      EXPECT_NEAR(ratio, 12.0 * std::sin(2.0 * std::numbers::pi / 24.0) / std::numbers::pi, 1e-5)
          << "k=" << kk;
    }
  }
}

// A scene with shaped particles: every snapshot holds angle, semi_axis_a, semi_axis_b and
// exponent, and /outlines/NNNNNN the particles' outline polygons, which snapshots.xmf shows
// as an "outlines" grid (checked by tests/io/check_xdmf.py: every DataItem, the polygons'
// areas and centres against the datasets); a disc-only store writes none of it. Through a
// failed write (its staged outlines removed) and a resume (the outlines of the dropped
// snapshots removed, the kept ones listed again).
TEST(SnapshotWriter, ShapedParticlesCarryTheirShapeAndOutlines) {
  ScratchDir dir;
  const auto check_xdmf = [&](const std::string& when, bool shaped) {
    MPI_Barrier(MPI_COMM_WORLD);
    if (comm_rank() != 0) return;
    const std::string log = dir / "check_xdmf.log";
    const std::string command = "/usr/bin/python3 '" + std::string(DEM2D_SOURCE_DIR) +
                                "/tests/io/check_xdmf.py' '" + (dir / "snapshots.xmf") + "' > '" +
                                log + "' 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0) << when << ":\n" << read_text(log);
    const std::string xmf = read_text(dir / "snapshots.xmf");
    EXPECT_EQ(count(xmf, "<Grid Name=\"outlines\""),
              shaped ? count(xmf, "<Grid Name=\"particles\"") : 0);
    EXPECT_EQ(count(xmf, "TopologyType=\"Polygon\" NumberOfElements=\"7\" NodesPerElement=\"24\""),
              count(xmf, "<Grid Name=\"outlines\""));
  };
  const int n = 7;
  {
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    write_shaped(writer, n, 0, 0.1);
    ParticleStore p;
    fill_shaped(p, n, 1);
    writer.fail_before_dataset_for_testing(1000);  // after the last dataset and the outlines
    EXPECT_THROW(writer.write(p, 0.2, 100), IoError);
    write_shaped(writer, n, 1, 0.2);
    write_shaped(writer, n, 2, 0.3);
  }
  check_xdmf("after three snapshots and a failed write", true);
  if (comm_rank() == 0) {
    H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
    ASSERT_GE(file.id, 0);
    EXPECT_EQ(group_members(file.id, "/outlines"),
              (std::set<std::string>{"000000", "000001", "000002"}));
    EXPECT_EQ(group_members(file.id, "/incomplete"), std::set<std::string>{});
    for (int v = 0; v < 3; ++v) check_shaped_snapshot(file.id, "00000" + std::to_string(v), n, v);
  }
  {
    const auto writer = SnapshotWriter::resume(MPI_COMM_WORLD, dir.path(), {}, 0.15, 1e-9);
    write_shaped(*writer, n, 3, 0.4);
  }
  check_xdmf("after a resume and one more snapshot", true);
  if (comm_rank() == 0) {
    H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
    ASSERT_GE(file.id, 0);
    EXPECT_EQ(group_members(file.id, "/outlines"), (std::set<std::string>{"000000", "000001"}));
    check_shaped_snapshot(file.id, "000000", n, 0);
    check_shaped_snapshot(file.id, "000001", n, 3);
  }
  {  // discs only: no outlines, no polygons
    SnapshotWriter writer(MPI_COMM_WORLD, dir.path(), test_materials());
    write_version(writer, 5, 0, 0.1);
  }
  check_xdmf("discs only", false);
  if (comm_rank() != 0) return;
  H5Closer file{H5Fopen((dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  EXPECT_EQ(H5Lexists(file.id, "/outlines", H5P_DEFAULT), 0);
  EXPECT_EQ(group_members(file.id, "/xdmf"), std::set<std::string>{"polyvertex_5"});
  EXPECT_EQ(group_members(file.id, "/snapshots/000000").count("semi_axis_a"), 0u);
}

// The snapshots of a shaped scene on any rank count hold what the serial run's hold: ellipses in
// a drum at 6 rad/s (crossing sectors, migrating) stepped on all ranks (MpiDomain) and on rank 0
// alone, each writing a snapshot every 500 steps; post/h5compare.py finds the two files
// bit-identical, the outlines included (matched by id), and check_xdmf.py accepts both.
TEST(SnapshotWriter, ShapedSnapshotsOnAnyRankCountAreTheSerialOnes) {
  ScratchDir dir;
  const Scene scene = testing_support::shaped_drum_scene(100, 0.6, 6.0, true);
  DecompositionOptions opt;
  opt.has_center = true;
  opt.center = scene.drum.center;
  opt.repartition_threshold = 1.05;
  opt.repartition_gap = 2;
  MpiDomain domain(MPI_COMM_WORLD, opt);
  Simulation par(scene, &domain);
  std::optional<Simulation> ser;
  std::unique_ptr<SnapshotWriter> ser_writer;
  if (comm_rank() == 0) {
    fs::create_directories(dir / "serial");
    ser.emplace(scene);
    ser_writer = std::make_unique<SnapshotWriter>(MPI_COMM_SELF, dir / "serial", scene.materials);
  }
  fs::path par_dir = dir / "parallel";
  if (comm_rank() == 0) fs::create_directories(par_dir);
  MPI_Barrier(MPI_COMM_WORLD);
  {
    SnapshotWriter par_writer(MPI_COMM_WORLD, par_dir.string(), scene.materials);
    for (int s = 0; s <= 2000; ++s) {
      if (s > 0) {
        par.step();
        if (ser) ser->step();
      }
      if (s % 500 != 0) continue;
      par_writer.write(par.particles(), par.time(), s);
      if (ser_writer) ser_writer->write(ser->particles(), ser->time(), s);
    }
  }
  ser_writer.reset();
  MPI_Barrier(MPI_COMM_WORLD);
  if (comm_rank() != 0) return;
  const std::string log = dir / "compare.log";
  const std::string py = "/usr/bin/python3 '" + std::string(DEM2D_SOURCE_DIR);
  const std::string compare = py + "/post/h5compare.py' '" + (dir / "serial/snapshots.h5") + "' '" +
                              (par_dir / "snapshots.h5").string() + "' > '" + log + "' 2>&1";
  EXPECT_EQ(std::system(compare.c_str()), 0) << read_text(log);
  for (const std::string& d : {dir / "serial", par_dir.string()}) {
    const std::string check =
        py + "/tests/io/check_xdmf.py' '" + d + "/snapshots.xmf' > '" + log + "' 2>&1";
    EXPECT_EQ(std::system(check.c_str()), 0) << read_text(log);
  }
  H5Closer file{H5Fopen((par_dir / "snapshots.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  EXPECT_EQ(group_members(file.id, "/outlines").size(), 5u);
}

TEST(ParallelFile, ErrorsNameTheFileAndTheObject) {
  ScratchDir dir;
  const std::string missing = dir / "no/such/t.h5";  // MPI-IO's own open fails on every rank
  expect_same_io_error_everywhere([&] { h5::ParallelFile::create(MPI_COMM_WORLD, missing); },
                                  "cannot create " + missing + ": ");
  const std::string path = dir / "t.h5";
  auto f = h5::ParallelFile::create(MPI_COMM_WORLD, path);
  f.create_group("/a/b");  // with its parent
  expect_same_io_error_everywhere([&] { f.create_group("/a/b"); },
                                  path + ": cannot create group '/a/b': ");
  const double x = 1.0;
  f.write_rows("/a/x", h5::rank0_rows(MPI_COMM_WORLD, 1), comm_rank() == 0 ? &x : nullptr);
  expect_same_io_error_everywhere(
      [&] { f.write_rows("/a/x", h5::rank0_rows(MPI_COMM_WORLD, 1), &x); },
      path + ": cannot create dataset '/a/x': ");
  f.close();
}

TEST(ParallelFile, RowRangeIsAnExclusiveScan) {
  const int r = comm_rank();
  const h5::RowRange range = h5::row_range(MPI_COMM_WORLD, static_cast<std::size_t>(r + 1));
  const auto s = static_cast<std::uint64_t>(comm_size());
  EXPECT_EQ(range.offset, static_cast<std::uint64_t>(r * (r + 1) / 2));
  EXPECT_EQ(range.count, static_cast<std::uint64_t>(r + 1));
  EXPECT_EQ(range.total, s * (s + 1) / 2);
}

// --- series.csv -------------------------------------------------------------------------

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, ',');) out.push_back(cell);
  return out;
}

bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

TEST(SeriesWriter, HeaderAndRowsRoundTripBitExactly) {
  ScratchDir dir;
  if (comm_rank() != 0) return;  // series.csv is rank 0's alone
  const std::string path = dir / "series.csv";
  SeriesRow row;
  row.time = 0.1;
  row.step = 1234567890123;
  row.particles = 240;
  row.contacts = 531;
  row.kinetic_energy = 1.0 / 3.0;
  row.rotational_energy = 4.9406564584124654e-324;  // smallest subnormal
  row.potential_energy = -1234.5678901234567;
  row.elastic_energy = 1.7976931348623157e308;
  row.dissipated_energy = std::nextafter(1.0, 2.0);
  row.drum_torque = -0.0;
  row.drum_power = 2.0 / 7.0 * 1e-17;
  row.drive_work = 6.02214076e23;
  row.passes = 3.25;
  {
    SeriesWriter w(path, true, true);
    w.write(row);
    SeriesRow second = row;
    second.time = 0.2;
    w.write(second);
    // Flushed row by row: readable before the writer closes.
    EXPECT_EQ(count(read_text(path), "\n"), 3u);
  }
  std::ifstream in(path);
  std::string header, line, second_line, extra;
  std::getline(in, header);
  std::getline(in, line);
  std::getline(in, second_line);
  EXPECT_FALSE(std::getline(in, extra));
  EXPECT_EQ(header,
            "time,step,particles,contacts,kinetic_energy,rotational_energy,potential_energy,"
            "elastic_energy,dissipated_energy,drum_torque,drum_power,drive_work,passes");
  const auto cells = split(line);
  ASSERT_EQ(cells.size(), 13u);
  const double doubles[] = {row.time,
                            row.kinetic_energy,
                            row.rotational_energy,
                            row.potential_energy,
                            row.elastic_energy,
                            row.dissipated_energy,
                            row.drum_torque,
                            row.drum_power,
                            row.drive_work,
                            row.passes};
  const int double_columns[] = {0, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  for (int i = 0; i < 10; ++i) {
    const std::string& cell = cells[static_cast<std::size_t>(double_columns[i])];
    EXPECT_TRUE(same_bits(std::strtod(cell.c_str(), nullptr), doubles[i]))
        << "column " << double_columns[i] << ": " << cell;
  }
  EXPECT_EQ(cells[1], "1234567890123");
  EXPECT_EQ(cells[2], "240");
  EXPECT_EQ(cells[3], "531");
  EXPECT_EQ(split(second_line)[0], "0.20000000000000001");
}

TEST(SeriesWriter, VerletHasNoPassesColumnAndInactiveWritesNothing) {
  ScratchDir dir;
  if (comm_rank() != 0) return;
  {
    SeriesWriter w(dir / "series.csv", false, true);
    w.write(SeriesRow{});
  }
  std::ifstream in(dir / "series.csv");
  std::string header, line;
  std::getline(in, header);
  std::getline(in, line);
  EXPECT_EQ(split(header), series_columns(false));
  EXPECT_EQ(split(header).back(), "drive_work");
  EXPECT_EQ(line, "0,0,0,0,0,0,0,0,0,0,0,0");
  {
    SeriesWriter inactive(dir / "other.csv", true, false);
    inactive.write(SeriesRow{});
  }
  EXPECT_FALSE(fs::exists(dir / "other.csv"));
  // Inactive on an unwritable path: no error either (only rank 0 writes).
  EXPECT_NO_THROW(SeriesWriter("/proc/dem2d_no/series.csv", false, false));
}

// lifters.csv: one row per bar, doubles read back bit for bit; a restart keeps the rows up to
// the checkpoint's time and drops the rest, a torn last row among them even when its time was
// cut short to a value below the checkpoint's.
TEST(LifterLog, RowsPerBarAndARestartKeepsTheRowsUpToItsTime) {
  ScratchDir dir;
  if (comm_rank() != 0) return;
  const std::string path = dir / "lifters.csv";
  const std::vector<LifterLoad> bars = {{12.5, 1.0 / 3.0, -2.0, 7.25, 3},
                                        {307.0, 0.0, 0.0, 0.0, 0}};
  {
    LifterLog log(path, true, false);
    log.write(0.125, bars);
    log.write(0.25, bars);
  }
  std::vector<std::string> lines;
  {
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
  }
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0], kLiftersHeader);
  EXPECT_EQ(lines[1], "0.125,0,12.5,0.33333333333333331,-2,7.25,3");
  EXPECT_EQ(lines[2], "0.125,1,307,0,0,0,0");
  EXPECT_TRUE(same_bits(std::strtod(split(lines[1])[3].c_str(), nullptr), 1.0 / 3.0));
  // A kill in the middle of the row of t = 0.375: "0." of it is left (read as 0 s).
  { std::ofstream(path, std::ios::app) << "0."; }
  {
    LifterLog resumed(path, true, false, 0.25);
    resumed.write(0.375, bars);
  }
  std::vector<std::string> after;
  {
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);) after.push_back(line);
  }
  ASSERT_EQ(after.size(), 7u);
  EXPECT_EQ(std::vector<std::string>(after.begin(), after.begin() + 5), lines);
  EXPECT_EQ(after[5], "0.375,0,12.5,0.33333333333333331,-2,7.25,3");
  {
    LifterLog earlier(path, true, false, 0.2);  // a checkpoint at 0.2: the rows of 0.25 and on go
  }
  std::ifstream in(path);
  std::string line;
  int count = 0;
  while (std::getline(in, line)) ++count;
  EXPECT_EQ(count, 3);
}

TEST(SeriesWriter, UnwritablePathIsAnIoErrorNamingIt) {
  try {
    SeriesWriter w("/proc/dem2d_no/series.csv", false, true);
    FAIL() << "no IoError";
  } catch (const IoError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("cannot create /proc/dem2d_no/series.csv: ", 0), 0u)
        << e.what();
  }
}

TEST(SeriesWriter, FullDiskIsAnIoError) {
  if (comm_rank() != 0) return;
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  try {
    SeriesWriter w("/dev/full", false, true);  // the header's flush fails
    FAIL() << "no IoError";
  } catch (const IoError& e) {
    EXPECT_EQ(std::string(e.what()), "cannot write /dev/full: No space left on device");
  }
}

// --- output directory -------------------------------------------------------------------

std::string host() {
  char name[256] = {};
  ::gethostname(name, sizeof name - 1);
  return name;
}

TEST(OutputDirectory, CreatesNestedDirectoriesAndLocksThemWhileTheRunLasts) {
  ScratchDir dir;
  const std::string out = dir / "a/b/c";
  const std::string lock = out + "/" + kOutputLockName;
  {
    const OutputLock held = claim_output_directory(MPI_COMM_WORLD, out, Claim::kNew);
    MPI_Barrier(MPI_COMM_WORLD);
    EXPECT_TRUE(fs::is_directory(out));
    EXPECT_TRUE(fs::exists(lock));  // and nothing else: the write probe is gone
    EXPECT_EQ(std::distance(fs::directory_iterator(out), fs::directory_iterator{}), 1);
    MPI_Barrier(MPI_COMM_WORLD);  // every rank looked before rank 0 probes again
    // This process is running: a second claim is refused, --overwrite or not.
    for (const Claim how : {Claim::kNew, Claim::kOverwrite, Claim::kContinue})
      expect_same_io_error_everywhere(
          [&] { claim_output_directory(MPI_COMM_WORLD, out, how); },
          "output directory '" + out + "' is in use by a dem2d run that is still running (pid ");
    EXPECT_TRUE(fs::exists(lock));  // the refused claims left the holder's lock alone
    MPI_Barrier(MPI_COMM_WORLD);
  }
  MPI_Barrier(MPI_COMM_WORLD);
  EXPECT_FALSE(fs::exists(lock));  // released when the run ends
  MPI_Barrier(MPI_COMM_WORLD);
  claim_output_directory(MPI_COMM_WORLD, out, Claim::kNew);  // an empty folder: fine again
}

TEST(OutputDirectory, AnotherRunsOutputIsRefusedUnlessOverwritten) {
  ScratchDir dir;
  const std::string out = dir / "run";
  if (comm_rank() == 0) {
    fs::create_directories(out);
    std::ofstream(out + "/series.csv") << "time\n";
    std::ofstream(out + "/snapshots.h5") << "x";
    // The lock of a run killed without a chance to remove it: no process has pid 2^22 + 1.
    std::ofstream(out + "/" + kOutputLockName) << host() << " 4194305\n";
  }
  MPI_Barrier(MPI_COMM_WORLD);
  expect_same_io_error_everywhere(
      [&] { claim_output_directory(MPI_COMM_WORLD, out, Claim::kNew); },
      "output directory '" + out +
          "' holds another run's output (series.csv, snapshots.h5); give this run a new folder "
          "with --output DIR, or --overwrite to replace that output");
  MPI_Barrier(MPI_COMM_WORLD);
  EXPECT_TRUE(fs::exists(out + "/series.csv"));  // refused: nothing touched
  EXPECT_TRUE(fs::exists(out + "/" + kOutputLockName));
  {
    const OutputLock held = claim_output_directory(MPI_COMM_WORLD, out, Claim::kOverwrite);
    MPI_Barrier(MPI_COMM_WORLD);
    EXPECT_FALSE(fs::exists(out + "/series.csv"));  // the old output is gone, not mixed in
    EXPECT_FALSE(fs::exists(out + "/snapshots.h5"));
    EXPECT_TRUE(fs::exists(out + "/" + kOutputLockName));
    MPI_Barrier(MPI_COMM_WORLD);
  }
}

// A killed run's lock names a pid that a later, unrelated process may hold: the lock is the
// dead run's all the same (nobody holds it locked) and every kind of claim takes it over.
TEST(OutputDirectory, StaleLockNamingALiveProcessIsTakenOver) {
  for (const Claim how : {Claim::kNew, Claim::kOverwrite, Claim::kContinue}) {
    ScratchDir dir;
    const std::string out = dir / "run";
    const std::string lock = out + "/" + kOutputLockName;
    if (comm_rank() == 0) {
      fs::create_directories(out);
      std::ofstream(lock) << host() << " " << ::getppid() << "\n";  // a live process
    }
    MPI_Barrier(MPI_COMM_WORLD);
    {
      const OutputLock held = claim_output_directory(MPI_COMM_WORLD, out, how);
      MPI_Barrier(MPI_COMM_WORLD);
      if (comm_rank() == 0) {
        std::ifstream in(lock);
        std::string h;
        long pid = 0;
        in >> h >> pid;
        EXPECT_EQ(pid, static_cast<long>(::getpid()));  // this run's lock now
      }
      MPI_Barrier(MPI_COMM_WORLD);
    }
    MPI_Barrier(MPI_COMM_WORLD);
    EXPECT_FALSE(fs::exists(lock));
    MPI_Barrier(MPI_COMM_WORLD);
  }
}

// A folder with a checkpoint: a new run is offered --restart first, and told what --overwrite
// discards.
TEST(OutputDirectory, ACheckpointThereOffersRestartFirst) {
  ScratchDir dir;
  const std::string out = dir / "run";
  if (comm_rank() == 0) {
    fs::create_directories(out);
    std::ofstream(out + "/series.csv") << "time\n";
    std::ofstream(out + "/checkpoint.h5") << "x";
  }
  MPI_Barrier(MPI_COMM_WORLD);
  expect_same_io_error_everywhere(
      [&] { claim_output_directory(MPI_COMM_WORLD, out, Claim::kNew); },
      "output directory '" + out +
          "' holds another run's output (series.csv, checkpoint.h5), which can be continued: "
          "resume it with --restart " +
          out +
          "/checkpoint.h5, or give this run a new folder with --output DIR; --overwrite "
          "replaces that output and discards its checkpoint");
  MPI_Barrier(MPI_COMM_WORLD);
  EXPECT_TRUE(fs::exists(out + "/checkpoint.h5"));
}

TEST(OutputDirectory, UnwritableIsTheSameIoErrorOnEveryRank) {
  ScratchDir dir;
  expect_same_io_error_everywhere(
      [] { claim_output_directory(MPI_COMM_WORLD, "/proc/dem2d_no", Claim::kNew); },
      "cannot write to output directory '/proc/dem2d_no': ");
  if (comm_rank() == 0) std::ofstream(dir / "plain_file") << "x";
  MPI_Barrier(MPI_COMM_WORLD);
  const std::string under_file = dir / "plain_file/sub";
  expect_same_io_error_everywhere(
      [&] { claim_output_directory(MPI_COMM_WORLD, under_file, Claim::kNew); },
      "cannot write to output directory '" + under_file + "': ");
  const std::string file_itself = dir / "plain_file";
  expect_same_io_error_everywhere(
      [&] { claim_output_directory(MPI_COMM_WORLD, file_itself, Claim::kNew); },
      "cannot write to output directory '" + file_itself + "': ");
}

}  // namespace
}  // namespace dem2d
