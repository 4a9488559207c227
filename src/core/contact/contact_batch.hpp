// ContactBatch: the particle-particle contacts of one force evaluation, gathered into
// contiguous arrays so that the contact law runs on SIMD packs (core/fast/simd.hpp).
//
// The pair loop (contact_engine.cpp) runs in three phases:
//   A. gather (scalar): for each candidate pair in canonical order, test for overlap and copy
//      the inputs of the pairs in contact here;
//   B. evaluate (SIMD): kinematics, contact law and rolling model, kPackSize contacts at a time
//      (the batch is padded to a whole number of packs with copies of its last contact);
//   C. scatter (scalar): forces, torques and histories back to the particles in canonical
//      pair order, so each particle's sum is ordered by partner id (docs/architecture.md).
// The law is the same template as for one contact, with selects instead of branches, so the
// results do not depend on which lane a contact lands in.
#pragma once

#include <array>
#include <cstdint>

#include "core/base/array.hpp"

namespace dem2d {

// Most history slots a contact model may declare (law + rolling + tracker + stepper).
inline constexpr std::size_t kMaxHistorySlots = 10;

// The history columns of a batch: slot s of contact c is old[s][c] before the step, fresh[s][c]
// after it.
struct HistoryColumns {
  std::array<Array<double>, kMaxHistorySlots> old, fresh;
};

// A batch's input columns followed by its old history columns (all of them are copied into the
// padding lanes).
template <std::size_t N>
std::array<Array<double>*, N + kMaxHistorySlots> with_history(
    const std::array<Array<double>*, N>& columns, HistoryColumns& h) {
  std::array<Array<double>*, N + kMaxHistorySlots> out{};
  for (std::size_t k = 0; k < N; ++k) out[k] = columns[k];
  for (std::size_t s = 0; s < kMaxHistorySlots; ++s) out[N + s] = &h.old[s];
  return out;
}

// What both batches share: the contact's list index and material pair, the history columns, and
// sizing and padding driven by the derived batch's two column lists, `inputs()` (what phase B
// reads: copied into the padding lanes) and `outputs()`.
template <class Derived>
struct BatchColumns {
  Array<std::int32_t> pair;   // index into the list
  Array<std::int32_t> coeff;  // material pair index into the coefficient table
  HistoryColumns history;
  // The history slots the kernel's model declares: only these columns are sized and copied.
  std::size_t width = kMaxHistorySlots;

  void reserve(std::size_t n) {
    if (pair.size() >= n) return;
    const auto in = self().inputs();
    for (std::size_t k = 0; k < used(in.size()); ++k) in[k]->resize(n);
    for (Array<double>* v : self().outputs()) v->resize(n);
    for (std::size_t s = 0; s < width; ++s) history.fresh[s].resize(n);
    pair.resize(n);
    coeff.resize(n);
  }
  // Copy contact `from` into slot `to` (padding).
  void copy(std::size_t to, std::size_t from) {
    const auto in = self().inputs();
    for (std::size_t k = 0; k < used(in.size()); ++k) (*in[k])[to] = (*in[k])[from];
    pair[to] = pair[from];
    coeff[to] = coeff[from];
  }

 private:
  Derived& self() { return static_cast<Derived&>(*this); }
  // The inputs in use: all but the history columns beyond `width` (they come last).
  std::size_t used(std::size_t inputs) const { return inputs - kMaxHistorySlots + width; }
};

struct ContactBatch : BatchColumns<ContactBatch> {
  // Inputs (phase A).
  Array<double> dx, dy;  // x_j - x_i
  Array<double> dist2;   // |x_j - x_i|^2
  Array<double> r_i, r_j, m_i, m_j;
  Array<double> vx, vy;     // v_i - v_j
  Array<double> spin;       // w_i r_i + w_j r_j
  Array<double> omega_rel;  // w_i - w_j
  Array<double> counted;    // 1: this rank books the contact's energies and count, 0: not
  // Each body's spin and angle, for a shape whose arms leave the normal (else not written).
  Array<double> w_i, w_j, th_i, th_j;
  // Outputs (phase B).
  Array<double> fx, fy;    // force on i (on j: the opposite)
  Array<double> t_i, t_j;  // torques on i and on j
  Array<double> overlap;   // delta / min(r_i, r_j)
  Array<double> ex, ey;    // the elastic normal force on i (ContactForceT::f_el)
  // Its torques on i and on j, for a shape whose arms leave the normal (else not written).
  Array<double> et_i, et_j;

  std::array<Array<double>*, 16 + kMaxHistorySlots> inputs() {
    return with_history<16>({&dx, &dy, &dist2, &r_i, &r_j, &m_i, &m_j, &vx, &vy, &spin, &omega_rel,
                             &counted, &w_i, &w_j, &th_i, &th_j},
                            history);
  }
  std::array<Array<double>*, 9> outputs() {
    return {&fx, &fy, &t_i, &t_j, &overlap, &ex, &ey, &et_i, &et_j};
  }
};

// The particle-wall contacts of one force evaluation, in the same three phases: the geometry
// (closest point, normal, wall velocity) is found in the scalar gather, the law runs on packs,
// and the scatter adds forces, energies, drive power and drum torque in wall-list order.
struct WallBatch : BatchColumns<WallBatch> {
  // Inputs (phase A).
  Array<double> delta, nx, ny;  // overlap; unit normal from the sphere towards the wall
  Array<double> r, m;
  Array<double> vx, vy;     // v_rel = (v_i - v_wall) + w_i r_i t
  Array<double> omega_rel;  // w_i - Omega_wall
  Array<double> wx, wy;     // wall velocity at the contact point (scatter only)
  Array<double> px, py;     // contact point (scatter only)
  // For a shape whose arms leave the normal (else not written): the arm (contact point minus
  // centre) and the radius of curvature at the contact.
  Array<double> ax, ay, r_eff;
  // Outputs (phase B).
  Array<double> fx, fy, torque, m_roll;
  Array<double> diss_law, el_law, diss_roll, el_roll;
  Array<double> ex, ey;  // the elastic normal force (ContactForceT::f_el)
  Array<double> et;      // its torque, for a shape whose arms leave the normal (else not written)

  std::array<Array<double>*, 11 + kMaxHistorySlots> inputs() {
    return with_history<11>({&delta, &nx, &ny, &r, &m, &vx, &vy, &omega_rel, &ax, &ay, &r_eff},
                            history);
  }
  std::array<Array<double>*, 15> outputs() {
    return {&wx,       &wy,     &px,        &py,      &fx, &fy, &torque, &m_roll,
            &diss_law, &el_law, &diss_roll, &el_roll, &ex, &ey, &et};
  }
};

}  // namespace dem2d
