#include "io/hdf5.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <mutex>

#include "core/errors.hpp"
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

RowRange row_range(MPI_Comm comm, std::size_t local_count) {
  const auto count = static_cast<std::uint64_t>(local_count);
  return {mpi::exclusive_scan_sum(comm, count), count, mpi::sum(comm, count)};
}

RowRange rank0_rows(MPI_Comm comm, std::size_t count) {
  const auto n = static_cast<std::uint64_t>(count);
  return {0, mpi::rank(comm) == 0 ? n : 0, n};
}

ParallelFile ParallelFile::create(MPI_Comm comm, const std::string& path) {
  silence_hdf5_error_printing();
  ParallelFile f(comm, path);
  auto create_failed = [&] {
    throw IoError(fmt::format("cannot create {}: {}", path, error_stack_detail()));
  };
  PropListHandle fapl(H5Pcreate(H5P_FILE_ACCESS));
  if (!fapl.valid()) create_failed();
  if (H5Pset_fapl_mpio(fapl.get(), comm, MPI_INFO_NULL) < 0) create_failed();
  // Metadata is written collectively: fewer, larger writes at many ranks.
  if (H5Pset_coll_metadata_write(fapl.get(), true) < 0) create_failed();
  f.file_ = FileHandle(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()));
  if (!f.file_.valid()) create_failed();
  return f;
}

void ParallelFile::fail(const std::string& operation, const std::string& object) const {
  throw IoError(
      fmt::format("{}: cannot {} '{}': {}", path_, operation, object, error_stack_detail()));
}

void ParallelFile::create_group(const std::string& name) {
  PropListHandle lcpl(check(H5Pcreate(H5P_LINK_CREATE), "create link properties for", name));
  check(H5Pset_create_intermediate_group(lcpl.get(), 1), "set link properties for", name);
  GroupHandle group(
      check(H5Gcreate2(file_.get(), name.c_str(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT),
            "create group", name));
  check(group.close(), "close group", name);
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
