// All of dem2d's HDF5 code: RAII handles and a parallel file that writes row-distributed
// datasets collectively.
//
// Every HDF5 call is checked; a failure throws IoError naming the file, the operation and
// the object, followed by the innermost messages of HDF5's error stack (HDF5's own printing
// of that stack to stderr is switched off the first time a file is opened here).
//
// Parallel model. A file is opened with the MPI-IO driver (H5Pset_fapl_mpio) on a
// communicator, also on one rank. Every ParallelFile member is collective: all ranks of the
// communicator call it, in the same order, with the same names and the same attribute
// values. A row-distributed dataset has `total` rows of `columns` values; rank r writes its
// `count` rows at row `offset`, where the offsets come from an exclusive scan of the counts
// (row_range; the collectives are parallel/comm.hpp's), so rank 0's rows come first, then
// rank 1's, and so on. The data transfer is collective (H5FD_MPIO_COLLECTIVE); a rank with no
// rows takes part with an empty selection.
#pragma once

#include <hdf5.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/shape/particles.hpp"  // FieldBase: particle fields as datasets (field_column)
#include "parallel/comm.hpp"         // MPI_Comm: the MPI-IO driver takes the communicator

namespace dem2d::h5 {

// Owns one HDF5 identifier and closes it with the matching H5?close function. close()
// reports the status (for the normal path, where it is checked); the destructor ignores it.
template <herr_t (*Close)(hid_t)>
class Handle {
 public:
  Handle() = default;
  explicit Handle(hid_t id) : id_(id) {}
  ~Handle() { close(); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, H5I_INVALID_HID)) {}
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      close();
      id_ = std::exchange(other.id_, H5I_INVALID_HID);
    }
    return *this;
  }

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  // Closes the identifier (if any); returns the close function's status, 0 if none was open.
  herr_t close() noexcept { return valid() ? Close(std::exchange(id_, H5I_INVALID_HID)) : 0; }

 private:
  hid_t id_ = H5I_INVALID_HID;
};

using FileHandle = Handle<H5Fclose>;
using GroupHandle = Handle<H5Gclose>;
using DatasetHandle = Handle<H5Dclose>;
using DataspaceHandle = Handle<H5Sclose>;
using PropListHandle = Handle<H5Pclose>;
using AttributeHandle = Handle<H5Aclose>;
using DatatypeHandle = Handle<H5Tclose>;

// The rows one rank contributes to a row-distributed dataset.
struct RowRange {
  std::uint64_t offset = 0;  // first global row of this rank: exclusive scan of the counts
  std::uint64_t count = 0;   // rows this rank writes
  std::uint64_t total = 0;   // rows of all ranks: sum of the counts
};

// Collective: the range of `local_count` rows on this rank, in rank order.
RowRange row_range(MPI_Comm comm, std::size_t local_count);

// The same range on every rank for data that rank 0 alone writes (a small table).
RowRange rank0_rows(MPI_Comm comm, std::size_t count);

// A particle field as the rows of a dataset (snapshots.h5, checkpoint.h5): one row per
// particle of `columns` values of one element type. The one place that maps the store's field
// types to HDF5: Field<double> (1 double), Field<Vec2> (2 doubles, x and y), Field<int64_t>,
// Field<int32_t>.
struct FieldColumn {
  enum Element { kInt64, kInt32, kDouble };
  Element element = kDouble;
  const void* data = nullptr;  // the field's values, item 0 first
  std::size_t columns = 1;     // values per particle: 1, or 2 for a Vec2
};

// The column of `field`; std::nullopt for a field of any other type.
std::optional<FieldColumn> field_column(const FieldBase& field);
// "int64", "int32" or "double": the name ParallelFile::DatasetShape::type gives the element.
const char* element_name(FieldColumn::Element element);
// The native memory type a field's values are read back with (a Vec2 as two doubles). Throws
// std::logic_error for a field field_column() cannot hold.
hid_t memory_type(const FieldBase& field);

class ParallelFile {
 public:
  // Collective: creates `path` (truncating an existing file) with the MPI-IO driver.
  // Throws IoError "cannot create PATH: REASON" on failure (on the failing ranks; callers
  // that need agreement wrap it, see SnapshotWriter).
  static ParallelFile create(MPI_Comm comm, const std::string& path);

  ParallelFile(ParallelFile&&) noexcept = default;
  ParallelFile& operator=(ParallelFile&&) noexcept = default;
  ~ParallelFile() = default;  // closes the file, ignoring errors

  const std::string& path() const { return path_; }
  MPI_Comm comm() const { return comm_; }

  // Collective: opens the existing `path` for reading and writing with the MPI-IO driver.
  // Throws IoError "cannot open PATH: REASON" on failure (on the failing ranks, as create).
  static ParallelFile open(MPI_Comm comm, const std::string& path);

  // Creates the group at the absolute path `name`, with any missing parents. With
  // `track_order`, the group records the creation order of its members (members() lists
  // them in that order).
  void create_group(const std::string& name, bool track_order = false);

  // Collective: renames the link `from` to `to` (absolute paths; H5Lmove, the object is not
  // copied). The parent group of `to` must exist.
  void move_link(const std::string& from, const std::string& to);
  // Collective: a second name `link` (absolute path) for the existing object `target` (a hard
  // link, H5Lcreate_hard: the object is stored once and stays while any of its names does).
  // The parent group of `link` must exist.
  void hard_link(const std::string& target, const std::string& link);
  // Collective: removes the link `name` (H5Ldelete). The object's space in the file is not
  // reclaimed.
  void remove_link(const std::string& name);

  // Scalar attribute `attribute` on the object at `object` (an absolute path).
  void write_attribute(const std::string& object, const std::string& attribute, double value);
  void write_attribute(const std::string& object, const std::string& attribute, std::int64_t value);
  // A fixed-length, null-terminated string (parallel HDF5 writes no variable-length data).
  void write_attribute(const std::string& object, const std::string& attribute,
                       const std::string& value);

  // Creates the dataset `name` (absolute path) with range.total rows of `columns` values
  // (rank 1 when columns == 1, else rank 2) and writes this rank's range.count rows from
  // `data` (row-major, range.count * columns values) collectively. `data` may be null when
  // range.count is 0.
  void write_rows(const std::string& name, const RowRange& range, const double* data,
                  std::size_t columns = 1);
  void write_rows(const std::string& name, const RowRange& range, const std::int64_t* data,
                  std::size_t columns = 1);
  void write_rows(const std::string& name, const RowRange& range, const std::int32_t* data,
                  std::size_t columns = 1);
  // Single precision (IEEE 754 binary32): drawing data, not state (snapshots.h5's outlines).
  void write_rows(const std::string& name, const RowRange& range, const float* data,
                  std::size_t columns = 1);
  // The first range.count items of the particle field `field` as the rows of the dataset
  // `name` (field_column: the field's type decides the element type and the columns), as
  // write_rows. Throws std::logic_error for a field field_column() cannot hold.
  void write_field(const std::string& name, const RowRange& range, const FieldBase& field);
  // A 1-D dataset of fixed-length, null-terminated strings; `values` must be the same on all
  // ranks (rank 0's are written).
  void write_strings(const std::string& name, const std::vector<std::string>& values);

  // Reading. Not collective (every rank may read alone), but every rank that reads sees the
  // same file. A missing object or a failed read throws IoError "PATH: cannot ... 'OBJECT':
  // REASON".
  // Whether the link `name` (an absolute path whose parent groups exist) exists.
  bool link_exists(const std::string& name) const;
  // The names of the members of the group `group`: in creation order when the group tracks
  // it (create_group's `track_order`), else in name order.
  std::vector<std::string> group_members(const std::string& group) const;
  double read_double_attribute(const std::string& object, const std::string& attribute) const;
  std::int64_t read_int64_attribute(const std::string& object, const std::string& attribute) const;
  // A fixed-length string attribute (what write_attribute writes for a std::string).
  std::string read_string_attribute(const std::string& object, const std::string& attribute) const;
  // A 1-D dataset of fixed-length strings (what write_strings writes).
  std::vector<std::string> read_strings(const std::string& name) const;
  // The element type and shape of the dataset `name`: type "int64", "int32", "double" or
  // "float" (IoError for any other), `rows` its first dimension, `columns` its second (1 for a 1-D
  // dataset; IoError for more than 2 dimensions).
  struct DatasetShape {
    std::string type;
    std::uint64_t rows = 0;
    std::size_t columns = 1;
  };
  DatasetShape dataset_shape(const std::string& name) const;

  // Collective: pushes everything written so far to the file (H5Fflush, global scope).
  void flush();
  // Collective: closes the file, checking the result. Later calls do nothing.
  void close();

 private:
  ParallelFile(MPI_Comm comm, std::string path) : comm_(comm), path_(std::move(path)) {}
  void write_scalar_attribute(const std::string& object, const std::string& attribute,
                              hid_t file_type, hid_t memory_type, const void* value);
  void read_scalar_attribute(const std::string& object, const std::string& attribute,
                             hid_t memory_type, void* value) const;
  void write_rows_typed(const std::string& name, const RowRange& range, hid_t file_type,
                        hid_t memory_type, const void* data, std::size_t columns);
  [[noreturn]] void fail(const std::string& operation, const std::string& object) const;
  template <class Id>
  Id check(Id status, const std::string& operation, const std::string& object) const {
    if (status < 0) fail(operation, object);
    return status;
  }

  MPI_Comm comm_ = MPI_COMM_NULL;
  std::string path_;
  FileHandle file_;
};

}  // namespace dem2d::h5
