// MpiDomain: the Domain verbs over MPI. Today: reductions only, which are exact (max, logical
// or, integer sums) or order-fixed (double sums gathered and added in rank order), so they
// give the same bits on every rank. The angular-sector decomposition (migrate, exchange_halo,
// refresh_ghosts) is issue 3.
#pragma once

#include <mpi.h>

#include "core/domain.hpp"

namespace dem2d {

class MpiDomain final : public Domain {
 public:
  explicit MpiDomain(MPI_Comm comm);
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  double sum(double x) const override;
  double max(double x) const override;
  std::int64_t sum(std::int64_t x) const override;
  bool any(bool x) const override;

 private:
  MPI_Comm comm_;
  int rank_ = 0;
  int size_ = 1;
};

}  // namespace dem2d
