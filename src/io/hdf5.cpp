#include "io/hdf5.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <type_traits>

#include "core/base/errors.hpp"
#include "parallel/comm.hpp"

namespace dem2d::h5 {
namespace {

// HDF5 prints its error stack to stderr by default; dem2d reports errors through IoError
// (with the stack's innermost messages) instead.
void silence_hdf5_error_printing() {
  static std::once_flag once;
  std::call_once(once, [] { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); });
}

// The innermost (most specific) messages of the current HDF5 error stack, outermost first,
// e.g. "file open failed: MPI_ERR_NO_SUCH_FILE: no such file"; then clears the stack.
std::string error_stack_detail() {
  std::vector<std::string> messages;  // innermost first
  auto collect = [](unsigned, const H5E_error2_t* e, void* out) -> herr_t {
    auto& m = *static_cast<std::vector<std::string>*>(out);
    if (e->desc != nullptr && *e->desc != '\0' && m.size() < 2) m.emplace_back(e->desc);
    return 0;
  };
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, collect, &messages);
  H5Eclear2(H5E_DEFAULT);
  if (messages.empty()) return "unknown HDF5 error";
  std::reverse(messages.begin(), messages.end());
  std::string detail = messages.front();
  for (std::size_t i = 1; i < messages.size(); ++i) detail += ": " + messages[i];
  return detail;
}

}  // namespace

static_assert(sizeof(Vec2) == 2 * sizeof(double) && std::is_standard_layout_v<Vec2>,
              "a Vec2 field is written as N x 2 doubles");

std::optional<FieldColumn> field_column(const FieldBase& field) {
  if (const auto* d = dynamic_cast<const Field<double>*>(&field))
    return FieldColumn{FieldColumn::kDouble, d->data(), 1};
  if (const auto* v = dynamic_cast<const Field<Vec2>*>(&field))
    return FieldColumn{FieldColumn::kDouble, v->data(), 2};
  if (const auto* i = dynamic_cast<const Field<std::int64_t>*>(&field))
    return FieldColumn{FieldColumn::kInt64, i->data(), 1};
  if (const auto* i = dynamic_cast<const Field<std::int32_t>*>(&field))
    return FieldColumn{FieldColumn::kInt32, i->data(), 1};
  return std::nullopt;
}

const char* element_name(FieldColumn::Element element) {
  switch (element) {
    case FieldColumn::kInt64:
      return "int64";
    case FieldColumn::kInt32:
      return "int32";
    case FieldColumn::kDouble:
      break;
  }
  return "double";
}

namespace {

FieldColumn writable_column(const FieldBase& field) {
  const std::optional<FieldColumn> c = field_column(field);
  if (!c) throw std::logic_error("particle field '" + field.name() + "' has no HDF5 type");
  return *c;
}

}  // namespace

hid_t memory_type(const FieldBase& field) {
  switch (writable_column(field).element) {
    case FieldColumn::kInt64:
      return H5T_NATIVE_INT64;
    case FieldColumn::kInt32:
      return H5T_NATIVE_INT32;
    case FieldColumn::kDouble:
      break;
  }
  return H5T_NATIVE_DOUBLE;
}

RowRange row_range(MPI_Comm comm, std::size_t local_count) {
  const auto count = static_cast<std::uint64_t>(local_count);
  return {mpi::exclusive_scan_sum(comm, count), count, mpi::sum(comm, count)};
}

RowRange rank0_rows(MPI_Comm comm, std::size_t count) {
  const auto n = static_cast<std::uint64_t>(count);
  return {0, mpi::rank(comm) == 0 ? n : 0, n};
}

namespace {

// The file access properties of a ParallelFile: the MPI-IO driver on `comm`, metadata written
// collectively (fewer, larger writes at many ranks), and ROMIO's data sieving off: the
// metadata's small pieces scattered over the file are written as they are, not as a
// read-modify-write of a 512 KiB window around them (which made every snapshot read and write
// 512 KiB whatever its size). An invalid handle on failure.
PropListHandle mpio_access(MPI_Comm comm) {
  PropListHandle fapl(H5Pcreate(H5P_FILE_ACCESS));
  if (!fapl.valid()) return fapl;
  const mpi::IoHints hints;  // the property list keeps its own copy
  const bool ok = H5Pset_fapl_mpio(fapl.get(), comm, hints.get()) >= 0 &&
                  H5Pset_coll_metadata_write(fapl.get(), true) >= 0;
  return ok ? std::move(fapl) : PropListHandle();
}

}  // namespace

ParallelFile ParallelFile::create(MPI_Comm comm, const std::string& path) {
  silence_hdf5_error_printing();
  ParallelFile f(comm, path);
  const PropListHandle fapl = mpio_access(comm);
  if (fapl.valid())
    f.file_ = FileHandle(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()));
  if (!f.file_.valid())
    throw IoError(fmt::format("cannot create {}: {}", path, error_stack_detail()));
  return f;
}

ParallelFile ParallelFile::open(MPI_Comm comm, const std::string& path) {
  silence_hdf5_error_printing();
  ParallelFile f(comm, path);
  const PropListHandle fapl = mpio_access(comm);
  if (fapl.valid()) f.file_ = FileHandle(H5Fopen(path.c_str(), H5F_ACC_RDWR, fapl.get()));
  if (!f.file_.valid())
    throw IoError(fmt::format("cannot open {}: {}", path, error_stack_detail()));
  return f;
}

void ParallelFile::fail(const std::string& operation, const std::string& object) const {
  throw IoError(
      fmt::format("{}: cannot {} '{}': {}", path_, operation, object, error_stack_detail()));
}

void ParallelFile::create_group(const std::string& name, bool track_order) {
  PropListHandle lcpl(check(H5Pcreate(H5P_LINK_CREATE), "create link properties for", name));
  check(H5Pset_create_intermediate_group(lcpl.get(), 1), "set link properties for", name);
  PropListHandle gcpl(check(H5Pcreate(H5P_GROUP_CREATE), "create group properties for", name));
  if (track_order)
    check(H5Pset_link_creation_order(gcpl.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED),
          "set group properties for", name);
  GroupHandle group(
      check(H5Gcreate2(file_.get(), name.c_str(), lcpl.get(), gcpl.get(), H5P_DEFAULT),
            "create group", name));
  check(group.close(), "close group", name);
}

void ParallelFile::move_link(const std::string& from, const std::string& to) {
  check(H5Lmove(file_.get(), from.c_str(), file_.get(), to.c_str(), H5P_DEFAULT, H5P_DEFAULT),
        "move link", from + "' to '" + to);
}

void ParallelFile::hard_link(const std::string& target, const std::string& link) {
  check(H5Lcreate_hard(file_.get(), target.c_str(), file_.get(), link.c_str(), H5P_DEFAULT,
                       H5P_DEFAULT),
        "link", link + "' to '" + target);
}

void ParallelFile::remove_link(const std::string& name) {
  check(H5Ldelete(file_.get(), name.c_str(), H5P_DEFAULT), "remove link", name);
}

bool ParallelFile::link_exists(const std::string& name) const {
  return check(H5Lexists(file_.get(), name.c_str(), H5P_DEFAULT), "look up", name) > 0;
}

std::vector<std::string> ParallelFile::group_members(const std::string& group) const {
  GroupHandle g(check(H5Gopen2(file_.get(), group.c_str(), H5P_DEFAULT), "open group", group));
  PropListHandle gcpl(check(H5Gget_create_plist(g.get()), "read properties of", group));
  unsigned order = 0;
  check(H5Pget_link_creation_order(gcpl.get(), &order), "read properties of", group);
  const H5_index_t index =
      (order & H5P_CRT_ORDER_TRACKED) != 0 ? H5_INDEX_CRT_ORDER : H5_INDEX_NAME;
  std::vector<std::string> names;
  auto collect = [](hid_t, const char* name, const H5L_info_t*, void* out) -> herr_t {
    static_cast<std::vector<std::string>*>(out)->emplace_back(name);
    return 0;
  };
  check(H5Literate(g.get(), index, H5_ITER_INC, nullptr, collect, &names), "list group", group);
  return names;
}

double ParallelFile::read_double_attribute(const std::string& object,
                                           const std::string& attribute) const {
  double value = 0.0;
  read_scalar_attribute(object, attribute, H5T_NATIVE_DOUBLE, &value);
  return value;
}

std::int64_t ParallelFile::read_int64_attribute(const std::string& object,
                                                const std::string& attribute) const {
  std::int64_t value = 0;
  read_scalar_attribute(object, attribute, H5T_NATIVE_INT64, &value);
  return value;
}

std::string ParallelFile::read_string_attribute(const std::string& object,
                                                const std::string& attribute) const {
  const std::string what = object + "@" + attribute;
  AttributeHandle attr(check(
      H5Aopen_by_name(file_.get(), object.c_str(), attribute.c_str(), H5P_DEFAULT, H5P_DEFAULT),
      "open attribute", what));
  DatatypeHandle type(check(H5Aget_type(attr.get()), "read the type of", what));
  if (H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) != 0)
    throw IoError(fmt::format("{}: cannot read '{}': not a fixed-length string", path_, what));
  const std::size_t width = H5Tget_size(type.get());
  std::vector<char> buffer(width + 1, '\0');
  check(H5Aread(attr.get(), type.get(), buffer.data()), "read attribute", what);
  return std::string(buffer.data());
}

std::vector<std::string> ParallelFile::read_strings(const std::string& name) const {
  DatasetHandle d(check(H5Dopen2(file_.get(), name.c_str(), H5P_DEFAULT), "open dataset", name));
  DatatypeHandle type(check(H5Dget_type(d.get()), "read the type of", name));
  if (H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) != 0)
    throw IoError(fmt::format("{}: cannot read '{}': not fixed-length strings", path_, name));
  DataspaceHandle space(check(H5Dget_space(d.get()), "read the shape of", name));
  const hssize_t n = check(H5Sget_simple_extent_npoints(space.get()), "read the shape of", name);
  const std::size_t width = H5Tget_size(type.get());
  std::vector<char> buffer(static_cast<std::size_t>(n) * width + 1, '\0');
  if (n > 0)
    check(H5Dread(d.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer.data()),
          "read dataset", name);
  std::vector<std::string> out;
  for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) {
    const char* s = buffer.data() + k * width;
    out.emplace_back(s, strnlen(s, width));
  }
  return out;
}

void ParallelFile::read_scalar_attribute(const std::string& object, const std::string& attribute,
                                         hid_t memory_type, void* value) const {
  const std::string what = object + "@" + attribute;
  AttributeHandle attr(check(
      H5Aopen_by_name(file_.get(), object.c_str(), attribute.c_str(), H5P_DEFAULT, H5P_DEFAULT),
      "open attribute", what));
  check(H5Aread(attr.get(), memory_type, value), "read attribute", what);
}

ParallelFile::DatasetShape ParallelFile::dataset_shape(const std::string& name) const {
  DatasetHandle d(check(H5Dopen2(file_.get(), name.c_str(), H5P_DEFAULT), "open dataset", name));
  DatatypeHandle type(check(H5Dget_type(d.get()), "read the type of", name));
  DataspaceHandle space(check(H5Dget_space(d.get()), "read the shape of", name));
  const int rank = check(H5Sget_simple_extent_ndims(space.get()), "read the shape of", name);
  std::array<hsize_t, 2> dims{0, 1};
  if (rank < 1 || rank > 2)
    throw IoError(fmt::format("{}: cannot read '{}': {} dimensions", path_, name, rank));
  check(H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr), "read the shape of", name);
  const H5T_class_t cls = H5Tget_class(type.get());
  const std::size_t size = H5Tget_size(type.get());
  DatasetShape shape{"", dims[0], rank == 2 ? static_cast<std::size_t>(dims[1]) : 1};
  if (cls == H5T_FLOAT && (size == 8 || size == 4)) shape.type = size == 8 ? "double" : "float";
  if (cls == H5T_INTEGER && H5Tget_sign(type.get()) == H5T_SGN_2 && (size == 8 || size == 4))
    shape.type = size == 8 ? "int64" : "int32";
  if (shape.type.empty())
    throw IoError(
        fmt::format("{}: cannot read '{}': not int64, int32, double or float", path_, name));
  return shape;
}

void ParallelFile::write_attribute(const std::string& object, const std::string& attribute,
                                   double value) {
  write_scalar_attribute(object, attribute, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value);
}

void ParallelFile::write_attribute(const std::string& object, const std::string& attribute,
                                   std::int64_t value) {
  write_scalar_attribute(object, attribute, H5T_STD_I64LE, H5T_NATIVE_INT64, &value);
}

void ParallelFile::write_attribute(const std::string& object, const std::string& attribute,
                                   const std::string& value) {
  const std::string what = object + "@" + attribute;
  DatatypeHandle type(check(H5Tcopy(H5T_C_S1), "create string type for", what));
  check(H5Tset_size(type.get(), value.size() + 1), "set string size for", what);
  check(H5Tset_strpad(type.get(), H5T_STR_NULLTERM), "set string padding for", what);
  write_scalar_attribute(object, attribute, type.get(), type.get(), value.c_str());
  check(type.close(), "close string type for", what);
}

void ParallelFile::write_scalar_attribute(const std::string& object, const std::string& attribute,
                                          hid_t file_type, hid_t memory_type, const void* value) {
  const std::string what = object + "@" + attribute;
  DataspaceHandle space(check(H5Screate(H5S_SCALAR), "create dataspace for", what));
  AttributeHandle attr(
      check(H5Acreate_by_name(file_.get(), object.c_str(), attribute.c_str(), file_type,
                              space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
            "create attribute", what));
  check(H5Awrite(attr.get(), memory_type, value), "write attribute", what);
  check(attr.close(), "close attribute", what);
}

void ParallelFile::write_rows(const std::string& name, const RowRange& range, const double* data,
                              std::size_t columns) {
  write_rows_typed(name, range, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, data, columns);
}

void ParallelFile::write_rows(const std::string& name, const RowRange& range,
                              const std::int64_t* data, std::size_t columns) {
  write_rows_typed(name, range, H5T_STD_I64LE, H5T_NATIVE_INT64, data, columns);
}

void ParallelFile::write_rows(const std::string& name, const RowRange& range,
                              const std::int32_t* data, std::size_t columns) {
  write_rows_typed(name, range, H5T_STD_I32LE, H5T_NATIVE_INT32, data, columns);
}

void ParallelFile::write_rows(const std::string& name, const RowRange& range, const float* data,
                              std::size_t columns) {
  write_rows_typed(name, range, H5T_IEEE_F32LE, H5T_NATIVE_FLOAT, data, columns);
}

void ParallelFile::write_field(const std::string& name, const RowRange& range,
                               const FieldBase& field) {
  const FieldColumn c = writable_column(field);
  switch (c.element) {
    case FieldColumn::kInt64:
      return write_rows(name, range, static_cast<const std::int64_t*>(c.data), c.columns);
    case FieldColumn::kInt32:
      return write_rows(name, range, static_cast<const std::int32_t*>(c.data), c.columns);
    case FieldColumn::kDouble:
      break;
  }
  write_rows(name, range, static_cast<const double*>(c.data), c.columns);
}

void ParallelFile::write_strings(const std::string& name, const std::vector<std::string>& values) {
  // Fixed-length strings: parallel HDF5 cannot write variable-length data collectively.
  std::size_t width = 1;
  for (const auto& v : values) width = std::max(width, v.size() + 1);
  std::vector<char> buffer(values.size() * width, '\0');
  for (std::size_t i = 0; i < values.size(); ++i)
    std::copy(values[i].begin(), values[i].end(), buffer.begin() + static_cast<long>(i * width));
  DatatypeHandle type(check(H5Tcopy(H5T_C_S1), "create string type for", name));
  check(H5Tset_size(type.get(), width), "set string size for", name);
  check(H5Tset_strpad(type.get(), H5T_STR_NULLTERM), "set string padding for", name);
  write_rows_typed(name, rank0_rows(comm_, values.size()), type.get(), type.get(), buffer.data(),
                   1);
  check(type.close(), "close string type for", name);
}

void ParallelFile::write_rows_typed(const std::string& name, const RowRange& range, hid_t file_type,
                                    hid_t memory_type, const void* data, std::size_t columns) {
  const int rank = columns == 1 ? 1 : 2;
  const std::array<hsize_t, 2> file_dims{range.total, columns};
  const std::array<hsize_t, 2> start{range.offset, 0};
  const std::array<hsize_t, 2> count{range.count, columns};

  DataspaceHandle file_space(
      check(H5Screate_simple(rank, file_dims.data(), nullptr), "create dataspace for", name));
  DatasetHandle dataset(check(H5Dcreate2(file_.get(), name.c_str(), file_type, file_space.get(),
                                         H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                              "create dataset", name));
  if (range.total > 0) {  // every rank knows the total: all skip an empty dataset together
    DataspaceHandle memory_space(
        check(H5Screate_simple(rank, count.data(), nullptr), "create dataspace for", name));
    if (range.count > 0) {
      check(H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start.data(), nullptr,
                                count.data(), nullptr),
            "select rows of", name);
    } else {
      check(H5Sselect_none(file_space.get()), "select rows of", name);
      check(H5Sselect_none(memory_space.get()), "select rows of", name);
    }
    PropListHandle transfer(check(H5Pcreate(H5P_DATASET_XFER), "create transfer list for", name));
    check(H5Pset_dxpl_mpio(transfer.get(), H5FD_MPIO_COLLECTIVE), "set collective transfer for",
          name);
    static const char kNothing = 0;  // HDF5 wants a non-null buffer even for an empty selection
    check(H5Dwrite(dataset.get(), memory_type, memory_space.get(), file_space.get(), transfer.get(),
                   data != nullptr ? data : &kNothing),
          "write dataset", name);
  }
  check(dataset.close(), "close dataset", name);
}

void ParallelFile::flush() { check(H5Fflush(file_.get(), H5F_SCOPE_GLOBAL), "flush", path_); }

void ParallelFile::close() {
  if (file_.valid()) check(file_.close(), "close", path_);
}

}  // namespace dem2d::h5
