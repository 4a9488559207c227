// The shell's dynamics (docs/models.md, "The shell as finite elements"): M a + C v + K u = f(t)
// on the free degrees of freedom of an FeModel, C = alpha M + beta K (Rayleigh damping),
// integrated by Newmark's average acceleration (gamma = 1/2, beta = 1/4: implicit,
// unconditionally stable, second order, no numerical damping). For a fixed step h the effective
// stiffness K + (4 / h^2) M + (2 / h) C is factorised once (sparse LDL^T), and the initial
// acceleration takes one factorisation of M.
//
// The energy ledger is exact for this scheme: with the trapezoidal work of the loads
// W += (f_n + f_n+1) . (u_n+1 - u_n) / 2 and the damping's dissipation
// D += (v_n + v_n+1) . C (u_n+1 - u_n) / 2, kinetic + strain energy = initial energy + W - D at
// every step, to round-off (J per metre of depth).
#pragma once

#include "core/structure/fe_model.hpp"

namespace dem2d {

struct RayleighDamping {
  double mass = 0.0;       // alpha, 1/s
  double stiffness = 0.0;  // beta, s
};

class FeDynamics {
 public:
  FeDynamics(const FeModel& model, double step, RayleighDamping damping = {});

  // The state at t = 0 (full-size vectors; fixed dofs are held at zero) and the loads then; the
  // acceleration follows from M a = f - C v - K u. The ledger restarts.
  void start(const FeVector& u, const FeVector& v, const FeVector& f);
  // One step to t + h under the loads f_next at t + h.
  void step(const FeVector& f_next);

  double time() const { return time_; }
  double step_size() const { return h_; }
  FeVector displacement() const { return model_->expand_free(u_); }
  FeVector velocity() const { return model_->expand_free(v_); }
  FeVector acceleration() const { return model_->expand_free(a_); }
  double kinetic_energy() const;                     // v^T M v / 2
  double strain_energy() const;                      // u^T K u / 2
  double work() const { return work_; }              // of the loads since start
  double dissipated() const { return dissipated_; }  // by the damping since start

 private:
  const FeModel* model_;
  double h_;
  RayleighDamping damping_;
  FeSparse k_, m_, c_;
  Eigen::SimplicialLDLT<FeSparse> effective_;
  FeVector u_, v_, a_, f_;
  double time_ = 0.0, work_ = 0.0, dissipated_ = 0.0;
};

}  // namespace dem2d
