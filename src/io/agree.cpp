#include "io/agree.hpp"

#include "core/errors.hpp"

namespace dem2d {

void throw_if_any_rank_failed(MPI_Comm comm, const std::string& error) {
  int rank = 0;
  int size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int mine = error.empty() ? size : rank;
  int first = size;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == size) return;
  unsigned long length = rank == first ? error.size() : 0;
  MPI_Bcast(&length, 1, MPI_UNSIGNED_LONG, first, comm);
  std::string message = rank == first ? error : std::string(length, '\0');
  MPI_Bcast(message.data(), static_cast<int>(length), MPI_CHAR, first, comm);
  throw IoError(message);
}

}  // namespace dem2d
