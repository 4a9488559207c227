#include "parallel/mpi_domain.hpp"

#include <vector>

namespace dem2d {

MpiDomain::MpiDomain(MPI_Comm comm) : comm_(comm) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
}

// Sum in rank order on every rank: an MPI_Allreduce may add in any order.
double MpiDomain::sum(double x) const {
  std::vector<double> all(size_);
  MPI_Allgather(&x, 1, MPI_DOUBLE, all.data(), 1, MPI_DOUBLE, comm_);
  double s = 0.0;
  for (double v : all) s += v;
  return s;
}

double MpiDomain::max(double x) const {
  double r = 0.0;
  MPI_Allreduce(&x, &r, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return r;
}

std::int64_t MpiDomain::sum(std::int64_t x) const {
  std::int64_t r = 0;
  MPI_Allreduce(&x, &r, 1, MPI_INT64_T, MPI_SUM, comm_);
  return r;
}

bool MpiDomain::any(bool x) const {
  int in = x ? 1 : 0, out = 0;
  MPI_Allreduce(&in, &out, 1, MPI_INT, MPI_LOR, comm_);
  return out != 0;
}

}  // namespace dem2d
