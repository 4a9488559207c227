// ContactBatch: the particle-particle contacts of one force evaluation, gathered into
// contiguous arrays so that the contact law runs on SIMD packs (core/simd.hpp).
//
// The pair loop (simulation.cpp, force_kernel) runs in three phases:
//   A. gather (scalar): for each candidate pair in canonical order, test for overlap and copy
//      the inputs of the pairs in contact here;
//   B. evaluate (SIMD): kinematics, contact law and rolling model, kPackSize contacts at a time
//      (the batch is padded to a whole number of packs with copies of its last contact);
//   C. scatter (scalar): forces, torques and histories back to the particles in canonical
//      pair order, so each particle's sum is ordered by partner id (architecture.md).
// The law is the same template as for one contact, with selects instead of branches, so the
// results do not depend on which lane a contact lands in.
#pragma once

#include <cstdint>
#include <vector>

namespace dem2d {

struct ContactBatch {
  // Inputs (phase A).
  std::vector<std::int32_t> pair;   // index into the pair list
  std::vector<std::int32_t> coeff;  // material pair index into the PairTable
  std::vector<double> dx, dy;       // x_j - x_i
  std::vector<double> dist2;        // |x_j - x_i|^2
  std::vector<double> r_i, r_j, m_i, m_j;
  std::vector<double> vx, vy;       // v_i - v_j
  std::vector<double> spin;         // w_i r_i + w_j r_j
  std::vector<double> omega_rel;    // w_i - w_j
  std::vector<double> xi_old, mr_old;
  // Outputs (phase B).
  std::vector<double> fx, fy;       // force on i (on j: the opposite)
  std::vector<double> t_i, t_j;     // torques on i and on j
  std::vector<double> xi_new, mr_new;
  std::vector<double> overlap;      // delta / min(r_i, r_j)

  void reserve(std::size_t n) {
    if (pair.size() >= n) return;
    for (auto* v : {&dx, &dy, &dist2, &r_i, &r_j, &m_i, &m_j, &vx, &vy, &spin, &omega_rel,
                    &xi_old, &mr_old, &fx, &fy, &t_i, &t_j, &xi_new, &mr_new, &overlap})
      v->resize(n);
    pair.resize(n);
    coeff.resize(n);
  }
  // Copy contact `from` into slot `to` (padding).
  void copy(std::size_t to, std::size_t from) {
    for (auto* v : {&dx, &dy, &dist2, &r_i, &r_j, &m_i, &m_j, &vx, &vy, &spin, &omega_rel,
                    &xi_old, &mr_old})
      (*v)[to] = (*v)[from];
    pair[to] = pair[from];
    coeff[to] = coeff[from];
  }
};

}  // namespace dem2d
