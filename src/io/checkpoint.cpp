#include "io/checkpoint.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include "core/base/errors.hpp"
#include "io/checkpoint_checks.hpp"
#include "io/deck.hpp"
#include "io/hdf5.hpp"
#include "io/output_dir.hpp"
#include "io/series.hpp"
#include "io/text.hpp"

namespace dem2d {
namespace {

namespace fs = std::filesystem;

// The attribute that holds a dataset's checksum (rows_checksum, as an int64 of the same bits).
constexpr const char* kChecksumAttribute = "checksum";

// The scalars of a RunState as root attributes: the name and where the value lives.
struct RealAttribute {
  const char* name;
  double RunState::*member;
};
struct CountAttribute {
  const char* name;
  std::int64_t RunState::*member;
};
constexpr RealAttribute kReals[] = {{"time", &RunState::time},
                                    {"dt", &RunState::dt},
                                    {"skin", &RunState::skin},
                                    {"halo_width", &RunState::halo_width},
                                    {"balance0", &RunState::balance0},
                                    {"motion0", &RunState::motion0},
                                    {"potential0", &RunState::potential0},
                                    {"energy_floor", &RunState::energy_floor}};
constexpr CountAttribute kCounts[] = {{"step", &RunState::step},
                                      {"neighbor_builds", &RunState::neighbor_builds}};

// The pass counters and the grinding state, flattened (name, value) both ways.
std::vector<std::pair<const char*, std::int64_t*>> count_slots(RunState& s) {
  GrindingState& g = s.grinding;
  return {{"passes_total", &s.passes.total},
          {"passes_since_row", &s.passes.since_row},
          {"passes_steps_since_row", &s.passes.steps_since_row},
          {"unconverged_steps", &s.passes.unconverged_steps},
          {"next_id", &g.next_id},
          {"births_from", &g.births_from},
          {"breakages", &g.totals.breakages},
          {"fragments", &g.totals.fragments},
          {"fed_count", &g.totals.fed_count},
          {"discharged_count", &g.totals.discharged_count}};
}
std::vector<std::pair<const char*, double*>> real_slots(RunState& s) {
  GrindingState& g = s.grinding;
  return {{"next_feed_try", &g.next_feed_try},
          {"fed_mass", &g.totals.fed_mass},
          {"discharged_mass", &g.totals.discharged_mass}};
}
// The per-rank shares (/ranks/NAME).
std::vector<std::pair<const char*, double*>> share_slots(RunState& s) {
  return {{"dissipated", &s.rank_ledger.dissipated},
          {"drive_work", &s.rank_ledger.drive_work},
          {"fed_energy", &s.rank_ledger.fed},
          {"discharged_energy", &s.rank_ledger.discharged},
          {"drum_work", &s.rank_ledger.drum_work}};
}

// The mill analytics (/analysis): the window's samples, 8 values each (every rank holds the
// same) and their shell layers (/analysis/shell: the bits packed little-endian into
// kShellWords 64-bit words a sample), and the collision spectra summed over ranks (collective).
constexpr std::size_t kSampleValues = 8;
constexpr std::size_t kShellWords = (std::tuple_size_v<ShellBits> + 7) / 8;
void write_analysis(h5::ParallelFile& file, const RunState& s) {
  file.create_group("/analysis");
  std::vector<double> window;
  std::vector<std::int64_t> shell(kShellWords * s.mill_samples.size(), 0);
  for (std::size_t k = 0; k < s.mill_samples.size(); ++k) {
    const MillSample& m = s.mill_samples[k];
    window.insert(window.end(), {m.time, m.drum_work, m.airborne, m.corotating, m.surface_angle,
                                 m.toe, m.shoulder, m.charge_angle});
    for (std::size_t b = 0; b < m.shell.size(); ++b)
      shell[k * kShellWords + b / 8] |= static_cast<std::int64_t>(m.shell[b]) << (8 * (b % 8));
  }
  file.write_rows("/analysis/window", h5::rank0_rows(file.comm(), window.size()), window.data());
  file.write_rows("/analysis/shell", h5::rank0_rows(file.comm(), shell.size()), shell.data());
  std::vector<std::int64_t> counts = s.spectra_counts;
  std::vector<double> energies = s.spectra_energies;
  mpi::sum_in_place(file.comm(), std::span<std::int64_t>(counts));
  mpi::sum_in_place(file.comm(), std::span<double>(energies));
  file.write_rows("/analysis/spectra_counts", h5::rank0_rows(file.comm(), counts.size()),
                  counts.data());
  file.write_rows("/analysis/spectra_energies", h5::rank0_rows(file.comm(), energies.size()),
                  energies.data());
}

// The ore's size distributions (/grinding/sizes: initial, fed, product, SizeMasses::kClasses
// integers each, the product summed over ranks; collective) and the fines' mass.
constexpr std::size_t kSizeRows = 3 * SizeMasses::kClasses;
void write_sizes(h5::ParallelFile& file, const RunState& s) {
  file.create_group("/grinding");
  std::vector<std::int64_t> rows;
  std::vector<double> bounds;
  GrindingSizes g = s.grinding.sizes;
  mpi::sum_in_place(file.comm(), g.product.units());
  mpi::max_in_place(file.comm(), g.product.neg_low());
  mpi::max_in_place(file.comm(), g.product.high());
  for (const SizeMasses* m : {&g.initial, &g.fed, &g.product}) {
    rows.insert(rows.end(), m->units().begin(), m->units().end());
    bounds.insert(bounds.end(), m->neg_low().begin(), m->neg_low().end());
    bounds.insert(bounds.end(), m->high().begin(), m->high().end());
  }
  file.write_rows("/grinding/sizes", h5::rank0_rows(file.comm(), rows.size()), rows.data());
  file.write_rows("/grinding/size_bounds", h5::rank0_rows(file.comm(), bounds.size()),
                  bounds.data());
  const double fines = s.grinding.totals.fines_mass;
  file.write_rows("/grinding/fines_mass", h5::rank0_rows(file.comm(), 1), &fines);
}

// The resolved deck a checkpoint keeps and compares: without its [[particle]] tables (initial
// conditions, which the checkpoint's particles replace; a deck of 1e5 of them made a restart
// parse and compare 14 MB of TOML, 10 s instead of 0.2 s).
std::string deck_without_particles(const Scene& scene) {
  Scene s = scene;
  s.particles.clear();
  return resolved_deck_toml(s);
}

void write_state(h5::ParallelFile& file, const Simulation& sim, int ranks) {
  RunState s = sim.run_state();
  file.write_attribute("/", "format", std::string(kCheckpointFormat));
  file.write_attribute("/", "version", std::string(DEM2D_VERSION));
  file.write_attribute("/", "ranks", static_cast<std::int64_t>(ranks));
  file.write_attribute("/", "baseline_taken", static_cast<std::int64_t>(s.baseline_taken));
  file.write_attribute("/", "passes_last", static_cast<std::int64_t>(s.passes.last));
  for (const RealAttribute& a : kReals) file.write_attribute("/", a.name, s.*a.member);
  for (const CountAttribute& a : kCounts) file.write_attribute("/", a.name, s.*a.member);
  for (auto [name, value] : count_slots(s)) file.write_attribute("/", name, *value);
  for (auto [name, value] : real_slots(s)) file.write_attribute("/", name, *value);
  file.write_strings("/deck", {deck_without_particles(sim.scene())});
  file.create_group("/ranks");
  const h5::RowRange one = h5::row_range(file.comm(), 1);
  for (auto [name, value] : share_slots(s))
    file.write_rows(std::string("/ranks/") + name, one, value);
  file.create_group("/guards");
  std::vector<std::string> kinds, firsts;
  std::vector<std::int64_t> counts;
  for (const GuardRecord& g : s.guards) {
    kinds.push_back(g.kind);
    counts.push_back(g.count);
    firsts.push_back(g.first);
  }
  file.write_strings("/guards/kind", kinds);
  file.write_strings("/guards/first", firsts);
  file.write_rows("/guards/count", h5::rank0_rows(file.comm(), counts.size()), counts.data());
  write_analysis(file, s);
  write_sizes(file, s);
}

// The checksum of this rank's items of `f` summed over the ranks (collective).
std::uint64_t field_checksum(MPI_Comm comm, const FieldBase& f, std::size_t n) {
  std::vector<std::byte> items(n * f.bytes_per_item());
  for (std::size_t k = 0; k < n; ++k) f.pack(k, items.data() + k * f.bytes_per_item());
  return mpi::sum(comm, rows_checksum(items.data(), n, f.bytes_per_item()));
}

void write_particles(h5::ParallelFile& file, const ParticleStore& p) {
  file.create_group("/particles");
  const h5::RowRange rows = h5::row_range(file.comm(), p.n_owned());
  file.write_attribute("/particles", "count", static_cast<std::int64_t>(rows.total));
  for (const FieldBase* f : p.fields()) {
    const std::string name = "/particles/" + f->name();
    file.write_field(name, rows, *f);
    const std::uint64_t sum = field_checksum(file.comm(), *f, p.n_owned());
    file.write_attribute(name, kChecksumAttribute, static_cast<std::int64_t>(sum));
  }
}

void write_histories(h5::ParallelFile& file, const HistoryRecords& h) {
  file.create_group("/contacts");
  std::vector<std::int64_t> a(h.size()), b(h.size());
  std::vector<double> values;
  for (std::size_t k = 0; k < h.size(); ++k) {
    a[k] = h.a(k);
    b[k] = h.b(k);
    values.insert(values.end(), h.values(k), h.values(k) + h.width());
  }
  const h5::RowRange rows = h5::row_range(file.comm(), h.size());
  file.write_attribute("/contacts", "width", static_cast<std::int64_t>(h.width()));
  std::vector<std::byte> records(h.size() * h.record_bytes());
  for (std::size_t k = 0; k < h.size(); ++k) h.pack(k, records.data() + k * h.record_bytes());
  const std::uint64_t sum =
      mpi::sum(file.comm(), rows_checksum(records.data(), h.size(), h.record_bytes()));
  file.write_attribute("/contacts", kChecksumAttribute, static_cast<std::int64_t>(sum));
  file.write_rows("/contacts/a", rows, a.data());
  file.write_rows("/contacts/b", rows, b.data());
  if (h.width() > 0) file.write_rows("/contacts/history", rows, values.data(), h.width());
}

// ---------------------------------------------------------------------------------------------
// Reading: every rank opens the file alone, read-only.

class Reader {
 public:
  explicit Reader(const std::string& path) : path_(path) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    std::error_code ec;
    if (!fs::exists(path, ec)) fail("no such file");
    file_ = h5::FileHandle(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT));
    if (!file_.valid()) fail("not an HDF5 file");
  }
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(path_ + ": error: cannot restart from this checkpoint: " + why);
  }
  bool has(const char* name) const { return H5Lexists(file_.get(), name, H5P_DEFAULT) > 0; }
  bool has_attribute(const char* object, const char* name) const {
    return H5Aexists_by_name(file_.get(), object, name, H5P_DEFAULT) > 0;
  }
  const std::string& path() const { return path_; }
  // A scalar attribute of the object at `object` (the root by default).
  template <class T>
  T attribute(const char* name, hid_t type, const char* object = "/") const {
    h5::AttributeHandle a(H5Aopen_by_name(file_.get(), object, name, H5P_DEFAULT, H5P_DEFAULT));
    T value{};
    if (!a.valid() || H5Aread(a.get(), type, &value) < 0)
      fail(fmt::format("no attribute {} on {}", name, object));
    return value;
  }
  std::string string_attribute(const char* name) const;
  std::vector<std::string> strings(const std::string& name) const;
  // The dataset's rows (its first dimension) and values per row.
  std::array<hsize_t, 2> shape(const std::string& name) const;
  // All of the dataset as `type`, into `out` (which is sized to hold it).
  void read(const std::string& name, hid_t type, void* out) const;

 private:
  std::string path_;
  h5::FileHandle file_;
};

std::string Reader::string_attribute(const char* name) const {
  h5::AttributeHandle a(H5Aopen_by_name(file_.get(), "/", name, H5P_DEFAULT, H5P_DEFAULT));
  if (!a.valid()) fail(fmt::format("no attribute {}", name));
  h5::DatatypeHandle type(H5Aget_type(a.get()));
  std::string value(H5Tget_size(type.get()), '\0');
  if (H5Tget_class(type.get()) != H5T_STRING || H5Aread(a.get(), type.get(), value.data()) < 0)
    fail(fmt::format("attribute {} is not a string", name));
  return value.substr(0, value.find('\0'));
}

std::array<hsize_t, 2> Reader::shape(const std::string& name) const {
  h5::DatasetHandle d(H5Dopen2(file_.get(), name.c_str(), H5P_DEFAULT));
  if (!d.valid()) fail("no dataset " + name);
  h5::DataspaceHandle space(H5Dget_space(d.get()));
  std::array<hsize_t, 2> dims{0, 1};
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank < 1 || rank > 2 || H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr) < 0)
    fail("dataset " + name + " has an unexpected shape");
  return dims;
}

void Reader::read(const std::string& name, hid_t type, void* out) const {
  h5::DatasetHandle d(H5Dopen2(file_.get(), name.c_str(), H5P_DEFAULT));
  if (!d.valid() || H5Dread(d.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) < 0)
    fail("cannot read dataset " + name);
}

std::vector<std::string> Reader::strings(const std::string& name) const {
  const hsize_t n = shape(name)[0];
  h5::DatasetHandle d(H5Dopen2(file_.get(), name.c_str(), H5P_DEFAULT));
  h5::DatatypeHandle type(H5Dget_type(d.get()));
  const std::size_t width = H5Tget_size(type.get());
  if (H5Tget_class(type.get()) != H5T_STRING || width == 0) fail(name + " is not a string dataset");
  std::vector<char> buffer(n * width + 1, '\0');
  if (n > 0) read(name, type.get(), buffer.data());
  std::vector<std::string> out;
  for (hsize_t k = 0; k < n; ++k) {
    const char* s = buffer.data() + k * width;
    out.emplace_back(s, strnlen(s, width));
  }
  return out;
}

// A checkpoint written before the size distributions existed has none: they start empty, and
// the figures drawn from them (F80, P80, sizes.csv) cover the part of the run after the restart.
void read_sizes(const Reader& in, RunState& s, int my_rank) {
  if (!in.has("/grinding/sizes")) return;
  if (in.shape("/grinding/sizes")[0] != kSizeRows) in.fail("/grinding/sizes has the wrong length");
  if (in.shape("/grinding/size_bounds")[0] != 2 * kSizeRows)
    in.fail("/grinding/size_bounds has the wrong length");
  std::vector<std::int64_t> rows(kSizeRows);
  std::vector<double> bounds(2 * kSizeRows);
  in.read("/grinding/sizes", H5T_NATIVE_INT64, rows.data());
  in.read("/grinding/size_bounds", H5T_NATIVE_DOUBLE, bounds.data());
  GrindingSizes& g = s.grinding.sizes;
  std::size_t at = 0, b = 0;
  for (SizeMasses* m : {&g.initial, &g.fed, &g.product}) {
    for (std::int64_t& u : m->units()) u = rows[at++];
    for (double& x : m->neg_low()) x = bounds[b++];
    for (double& x : m->high()) x = bounds[b++];
  }
  if (my_rank != 0) g.product = SizeMasses{};  // rank 0 holds the sum
  in.read("/grinding/fines_mass", H5T_NATIVE_DOUBLE, &s.grinding.totals.fines_mass);
}

void read_spectra(const Reader& in, RunState& s);

void read_analysis(const Reader& in, RunState& s) {
  std::vector<double> window(in.shape("/analysis/window")[0]);
  if (window.size() % kSampleValues != 0) in.fail("/analysis/window has the wrong length");
  if (!window.empty()) in.read("/analysis/window", H5T_NATIVE_DOUBLE, window.data());
  for (std::size_t k = 0; k < window.size(); k += kSampleValues) {
    const double* v = window.data() + k;
    s.mill_samples.push_back({v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]});
  }
  // A checkpoint written before the window's shell profile existed has none: its samples keep
  // their other values and an empty profile, which scales every bin alike, so the window's toe
  // and shoulder come from the samples after the restart.
  if (!in.has("/analysis/shell")) return read_spectra(in, s);
  std::vector<std::int64_t> shell(in.shape("/analysis/shell")[0]);
  if (shell.size() != kShellWords * s.mill_samples.size())
    in.fail("/analysis/shell has the wrong length");
  if (!shell.empty()) in.read("/analysis/shell", H5T_NATIVE_INT64, shell.data());
  for (std::size_t k = 0; k < s.mill_samples.size(); ++k)
    for (std::size_t b = 0; b < s.mill_samples[k].shell.size(); ++b)
      s.mill_samples[k].shell[b] =
          static_cast<std::uint8_t>(shell[k * kShellWords + b / 8] >> (8 * (b % 8)));
  read_spectra(in, s);
}

void read_spectra(const Reader& in, RunState& s) {
  s.spectra_counts.resize(in.shape("/analysis/spectra_counts")[0]);
  s.spectra_energies.resize(in.shape("/analysis/spectra_energies")[0]);
  if (!s.spectra_counts.empty())
    in.read("/analysis/spectra_counts", H5T_NATIVE_INT64, s.spectra_counts.data());
  if (!s.spectra_energies.empty())
    in.read("/analysis/spectra_energies", H5T_NATIVE_DOUBLE, s.spectra_energies.data());
}

RunState read_state(const Reader& in, int my_rank, int my_size) {
  RunState s;
  if (in.string_attribute("format") != kCheckpointFormat)
    in.fail(fmt::format("its format is not '{}'", kCheckpointFormat));
  for (const RealAttribute& a : kReals)
    s.*a.member = in.attribute<double>(a.name, H5T_NATIVE_DOUBLE);
  for (const CountAttribute& a : kCounts)
    s.*a.member = in.attribute<std::int64_t>(a.name, H5T_NATIVE_INT64);
  for (auto [name, value] : count_slots(s))
    *value = in.attribute<std::int64_t>(name, H5T_NATIVE_INT64);
  for (auto [name, value] : real_slots(s)) *value = in.attribute<double>(name, H5T_NATIVE_DOUBLE);
  s.baseline_taken = in.attribute<std::int64_t>("baseline_taken", H5T_NATIVE_INT64) != 0;
  s.passes.last = static_cast<int>(in.attribute<std::int64_t>("passes_last", H5T_NATIVE_INT64));
  const auto ranks = static_cast<int>(in.attribute<std::int64_t>("ranks", H5T_NATIVE_INT64));
  if (ranks < 1) in.fail(fmt::format("its attribute ranks = {} is below 1", ranks));
  if (!std::isfinite(s.time) || s.time < 0.0 || s.step < 0)
    in.fail(fmt::format("its attributes time = {} and step = {} are not a moment of a run", s.time,
                        s.step));
  if (!std::isfinite(s.dt) || s.dt <= 0.0)
    in.fail(fmt::format("its attribute dt = {} is not above 0", s.dt));
  for (auto [name, value] : share_slots(s)) {
    const std::string path = std::string("/ranks/") + name;
    if (in.shape(path)[0] != static_cast<hsize_t>(ranks)) in.fail(path + " has the wrong length");
    std::vector<double> shares(static_cast<std::size_t>(ranks));
    in.read(path, H5T_NATIVE_DOUBLE, shares.data());
    // The same rank count: each rank its own share; another: rank 0 the sum, in rank order.
    double total = 0.0;
    for (const double x : shares) total += x;
    *value =
        ranks == my_size ? shares[static_cast<std::size_t>(my_rank)] : (my_rank == 0 ? total : 0.0);
  }
  const std::vector<std::string> kinds = in.strings("/guards/kind");
  const std::vector<std::string> firsts = in.strings("/guards/first");
  std::vector<std::int64_t> counts(kinds.size());
  if (firsts.size() != kinds.size() || in.shape("/guards/count")[0] != kinds.size())
    in.fail("the /guards datasets differ in length");
  if (!counts.empty()) in.read("/guards/count", H5T_NATIVE_INT64, counts.data());
  for (std::size_t k = 0; k < kinds.size(); ++k)
    s.guards.push_back({kinds[k], counts[k], firsts[k]});
  read_analysis(in, s);
  read_sizes(in, s, my_rank);
  return s;
}

void read_particles(const Reader& in, const Scene& scene, Resumption& r) {
  ParticleStore layout;  // the fields this scene's particles carry
  if (scene.breakage.present) layout.enable_damage();
  if (scene.drum.present) layout.enable_last_contact();
  if (has_shaped_particles(scene)) layout.enable_shape();
  r.n_particles = static_cast<std::size_t>(in.shape("/particles/id")[0]);
  for (const FieldBase* f : layout.fields()) {
    const std::string name = "/particles/" + f->name();
    if (!in.has(name.c_str())) in.fail("it holds no particle field '" + f->name() + "'");
    const std::array<hsize_t, 2> dims = in.shape(name);
    const std::size_t bytes = r.n_particles * f->bytes_per_item();
    const std::size_t value_bytes = h5::memory_type(*f) == H5T_NATIVE_INT32 ? 4 : 8;
    if (dims[0] != r.n_particles || dims[1] * value_bytes != f->bytes_per_item())
      in.fail("its particle field '" + f->name() + "' has the wrong shape");
    std::vector<std::byte> column(bytes);
    if (bytes) in.read(name, h5::memory_type(*f), column.data());
    r.columns.push_back(std::move(column));
  }
}

void read_histories(const Reader& in, Resumption& r) {
  const auto width =
      static_cast<std::size_t>(in.attribute<std::int64_t>("width", H5T_NATIVE_INT64, "/contacts"));
  const auto n = static_cast<std::size_t>(in.shape("/contacts/a")[0]);
  std::vector<std::int64_t> a(n), b(n);
  std::vector<double> values(n * width);
  if (in.shape("/contacts/b")[0] != n ||
      (width > 0 && (in.shape("/contacts/history")[0] != n ||
                     (width > 1 && in.shape("/contacts/history")[1] != width))))
    in.fail("its /contacts datasets differ in length");
  if (n > 0) {
    in.read("/contacts/a", H5T_NATIVE_INT64, a.data());
    in.read("/contacts/b", H5T_NATIVE_INT64, b.data());
    if (width > 0) in.read("/contacts/history", H5T_NATIVE_DOUBLE, values.data());
  }
  r.histories = HistoryRecords(width);
  for (std::size_t k = 0; k < n; ++k) r.histories.push_back(a[k], b[k], values.data() + k * width);
}

// The checkpoint's deck against this one: the physics must be the same.
void check_deck(const Reader& in, const Scene& scene, const std::string& path) {
  const std::vector<std::string> deck = in.strings("/deck");
  if (deck.size() != 1) in.fail("it holds no deck");
  const std::vector<std::string> differ =
      physics_differences(deck[0], deck_without_particles(scene));
  if (differ.empty()) return;
  std::string message = fmt::format(
      "{}: error: --restart {}: the deck's physics differs from the checkpoint's ({} {}); only "
      "output keys, run.duration, the title and the decomposition keys may change:",
      scene.deck_path, path, differ.size(), differ.size() == 1 ? "key" : "keys");
  for (const std::string& d : differ) message += "\n  " + d;
  throw InputError(message);
}

// A stored checksum (an old checkpoint has none: nothing to compare) against the values read.
void check_sum(const Reader& in, const std::string& object, std::uint64_t computed) {
  if (!in.has_attribute(object.c_str(), kChecksumAttribute)) return;
  const auto stored = static_cast<std::uint64_t>(
      in.attribute<std::int64_t>(kChecksumAttribute, H5T_NATIVE_INT64, object.c_str()));
  if (stored != computed)
    in.fail(
        fmt::format("{}: its values do not match the checksum written with them ({:#018x}, "
                    "read {:#018x}): the file was changed or damaged after it was written",
                    object, stored, computed));
}

// The particles and contacts read: the count written, their values sound (checkpoint_checks.hpp),
// then every dataset against its checksum.
void check_resumption(const Reader& in, const Scene& scene, const Resumption& r) {
  if (in.has_attribute("/particles", "count")) {
    const auto count = in.attribute<std::int64_t>("count", H5T_NATIVE_INT64, "/particles");
    if (count != static_cast<std::int64_t>(r.n_particles))
      in.fail(
          fmt::format("/particles: {} rows, its attribute count says {}", r.n_particles, count));
  }
  ParticleStore layout;
  if (scene.breakage.present) layout.enable_damage();
  if (scene.drum.present) layout.enable_last_contact();
  if (has_shaped_particles(scene)) layout.enable_shape();
  if (const std::string problem = resumption_problem(scene, layout, r); !problem.empty())
    in.fail(problem);
  for (std::size_t f = 0; f < layout.fields().size(); ++f) {
    const FieldBase& field = *layout.fields()[f];
    check_sum(in, "/particles/" + field.name(),
              rows_checksum(r.columns[f].data(), r.n_particles, field.bytes_per_item()));
  }
  const HistoryRecords& h = r.histories;
  std::vector<std::byte> records(h.size() * h.record_bytes());
  for (std::size_t k = 0; k < h.size(); ++k) h.pack(k, records.data() + k * h.record_bytes());
  check_sum(in, "/contacts", rows_checksum(records.data(), h.size(), h.record_bytes()));
}

Resumption read_all(const std::string& path, const Scene& scene, int rank, int size) {
  const Reader in(path);
  Resumption r;
  r.state = read_state(in, rank, size);
  check_deck(in, scene, path);
  read_particles(in, scene, r);
  read_histories(in, r);
  check_resumption(in, scene, r);
  return r;
}

// Flattens a TOML tree into dotted keys (arrays of tables by index: material[1].density) and
// the printed values.
void flatten(const toml::node& node, const std::string& key,
             std::map<std::string, std::string>& out) {
  if (const toml::table* t = node.as_table()) {
    for (auto&& [k, v] : *t)
      flatten(v, key.empty() ? std::string(k.str()) : key + "." + std::string(k.str()), out);
    return;
  }
  const toml::array* a = node.as_array();
  if (a != nullptr && a->is_array_of_tables()) {
    for (std::size_t i = 0; i < a->size(); ++i)
      flatten(*a->get(i), fmt::format("{}[{}]", key, i), out);
    return;
  }
  if (const auto* real = node.as_floating_point()) {
    out[key] = toml_number(real->get());  // the shortest text that reads back the same
    return;
  }
  std::ostringstream text;
  node.visit([&text](auto&& v) { text << v; });
  out[key] = text.str();
}

// Keys a restart may change: where and how often output goes, how long the run is, its title
// and how it is spread over ranks and stored.
bool may_change(const std::string& key) {
  return key.starts_with("output.") || key == "run.duration" || key == "title" ||
         key == "run.sectors_per_rank" || key == "run.repartition_threshold" ||
         key == "run.spatial_sort";
}

// The string value of the first "KEY": "..." in a JSON text (run.json), its escapes undone;
// empty when there is none.
std::string json_string(const std::string& text, const std::string& key) {
  const std::string start = "\"" + key + "\": \"";
  std::size_t at = text.find(start);
  if (at == std::string::npos) return {};
  std::string value;
  for (at += start.size(); at < text.size() && text[at] != '"'; ++at) {
    if (text[at] == '\\' && at + 1 < text.size()) ++at;
    value += text[at];
  }
  return value;
}

// Which run wrote the output in `dir`, as its run.json tells.
std::string folder_run(const fs::path& dir) {
  std::ifstream in(dir / kRunJsonFile);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string title = json_string(text, "title"), deck = json_string(text, "deck_path");
  if (deck.empty()) return "a run that left no run.json";
  return fmt::format("the run '{}' of the deck {} (its run.json)", title, deck);
}

// Why the output in `dir` is not the run `scene` continues from `restart`, empty if it may be.
std::string foreign_reason(const fs::path& dir, const std::string& restart, const Scene& scene) {
  std::error_code ec;
  std::ifstream series(dir / kSeriesFile);
  std::string header;
  const std::string mine =
      fmt::format("{}", fmt::join(series_columns(scene.run.integrator == IntegratorKind::kIterative,
                                                 is_ore_scene(scene), scene.drum.present),
                                  ","));
  if (series && std::getline(series, header) && header != mine)
    return fmt::format("its {} has other columns than this run's", kSeriesFile);
  const fs::path theirs = dir / kCheckpointFile;
  if (!fs::exists(theirs, ec) || fs::equivalent(theirs, restart, ec)) return {};
  try {
    const Reader in(theirs.string());
    const std::vector<std::string> deck = in.strings("/deck");
    if (deck.size() != 1) return {};
    const std::size_t n = physics_differences(deck[0], deck_without_particles(scene)).size();
    if (n > 0)
      return fmt::format("its {} holds a deck whose physics differs from this one's ({} {})",
                         kCheckpointFile, n, n == 1 ? "key" : "keys");
  } catch (const std::exception&) {  // not a checkpoint this reader can tell: no verdict
  }
  return {};
}

}  // namespace

void check_restart_folder(MPI_Comm comm, const std::string& dir, const std::string& restart,
                          const Scene& scene) {
  std::string error;
  const fs::path path = dir.empty() ? fs::path(".") : fs::path(dir);
  if (mpi::rank(comm) == 0) {
    const std::string reason = foreign_reason(path, restart, scene);
    if (!reason.empty())
      error = fmt::format(
          "output directory '{}' holds the output of another run, {}: {}; --restart {} continues "
          "the run of {}: give it that run's folder with --output {} or a new folder with "
          "--output DIR (the run this folder holds continues from its own checkpoint)",
          dir, folder_run(path), reason, restart, scene.deck_path,
          fs::path(restart).parent_path().string());
  }
  mpi::agree_on_failure<IoError>(comm, error);
}

std::vector<std::string> physics_differences(const std::string& checkpoint_deck,
                                             const std::string& deck) {
  std::map<std::string, std::string> was, now;
  flatten(toml::parse(checkpoint_deck), "", was);
  flatten(toml::parse(deck), "", now);
  std::vector<std::string> out;
  for (const auto& [key, value] : was) {
    if (may_change(key)) continue;
    const auto it = now.find(key);
    if (it == now.end())
      out.push_back(fmt::format("{}: checkpoint {}, deck (absent)", key, value));
    else if (it->second != value)
      out.push_back(fmt::format("{}: checkpoint {}, deck {}", key, value, it->second));
  }
  for (const auto& [key, value] : now)
    if (!may_change(key) && !was.contains(key))
      out.push_back(fmt::format("{}: checkpoint (absent), deck {}", key, value));
  return out;
}

Resumption read_checkpoint(MPI_Comm comm, const std::string& path, const Scene& scene) {
  std::string error;
  Resumption r;
  try {
    r = read_all(path, scene, mpi::rank(comm), mpi::size(comm));
  } catch (const InputError& e) {
    for (const std::string& m : e.messages()) error += (error.empty() ? "" : "\n") + m;
  } catch (const toml::parse_error& e) {
    error = path + ": error: cannot restart from this checkpoint: its deck does not parse";
  }
  mpi::agree_on_failure<InputError>(comm, error);
  return r;
}

void write_checkpoint(MPI_Comm comm, const std::string& path, const Simulation& sim) {
  const std::string temporary = path + ".tmp";
  const ParticleStore& p = sim.particles();
  const HistoryRecords histories = sim.histories();
  const std::uint64_t bytes =
      mpi::sum(comm, static_cast<std::uint64_t>(p.n_owned() * p.bytes_per_particle() +
                                                histories.size() * histories.record_bytes())) +
      2048 * (p.fields().size() + 16) + 16384;
  ensure_free_space(comm, temporary, bytes);
  std::string error;
  try {
    h5::ParallelFile file = h5::ParallelFile::create(comm, temporary);
    write_state(file, sim, mpi::size(comm));
    write_particles(file, sim.particles());
    write_histories(file, histories);
    file.close();
  } catch (const IoError& e) {
    error = e.what();
  }
  mpi::agree_on_failure<IoError>(comm, error);
  if (mpi::rank(comm) == 0) {
    std::error_code ec;
    fs::rename(temporary, path, ec);
    if (ec) {
      error = fmt::format("cannot write {}: {}", path, ec.message());
      fs::remove(temporary, ec);
    }
  }
  mpi::agree_on_failure<IoError>(comm, error);
}

}  // namespace dem2d
