// XdmfSidecar: snapshots.xmf, the XDMF 3 document that opens the snapshots of snapshots.h5 in
// ParaView (snapshots.hpp describes its grids). SnapshotWriter tells it which snapshots the
// HDF5 file holds (SnapshotInfo); it builds the text and keeps the file: written whole through
// a temporary file and a rename, or grown by one snapshot in O(1), its <Grid> and the fixed
// closing trailer (</Grid></Domain></Xdmf>) written over the old trailer in place.
//
// Rank 0 only; nothing here is collective. Each member returns an error message, empty on
// success, for the writer to agree on across ranks.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "io/snapshots.hpp"

namespace dem2d {

class XdmfSidecar {
 public:
  // `xmf_path`: the sidecar's path; `h5_name`: the HDF5 file as the sidecar names it (its file
  // name: the two files sit in the same folder).
  XdmfSidecar(std::string xmf_path, std::string h5_name)
      : path_(std::move(xmf_path)), h5_name_(std::move(h5_name)) {}

  const std::string& path() const { return path_; }

  // The whole file for `snapshots` (temporary file and rename); removes the file when there
  // are none.
  std::string rewrite(const std::vector<SnapshotInfo>& snapshots,
                      const std::vector<std::string>& material_names);
  // Whether append() can add a snapshot: the file is there as this sidecar last wrote it. Not
  // for the first snapshot, after a failed write, or when the file has gone: rewrite() then.
  bool can_append() const;
  // Adds `snapshot` in place, O(1) (can_append() must hold). On a failure the old trailer is
  // put back and the file cut after it (best effort).
  std::string append(const SnapshotInfo& snapshot, const std::vector<std::string>& material_names);
  // Syncs the file and its folder to disk (fsync), so that they survive a crash of the machine.
  std::string sync() const;

 private:
  std::string path_;
  std::string h5_name_;
  std::optional<long> trailer_;  // offset of the trailer in the file, while it is valid
};

}  // namespace dem2d
