// PairTable: contact coefficients for every ordered pair of materials, computed once.
//
// Effective moduli (physics.md section 2):
//   1/E* = (1 - nu_i^2)/E_i + (1 - nu_j^2)/E_j
//   1/G* = 2 (2 - nu_i)(1 + nu_i)/E_i + 2 (2 - nu_j)(1 + nu_j)/E_j
// Restitution, friction and rolling friction of a pair come from its [[interaction]] entry or,
// coefficient by coefficient, from the mean of the two materials' values.
#pragma once

#include <vector>

#include "core/scene.hpp"

namespace dem2d {

struct PairCoeffs {
  double e_star = 0.0;         // Pa
  double g_star = 0.0;         // Pa
  double restitution = 1.0;    // asked
  double mu_s = 0.0;           // sliding friction
  double mu_r = 0.0;           // rolling friction
  // hertz-mindlin: F_d = -2 sqrt(5/6) beta sqrt(S m*) v; stored as damp = -2 sqrt(5/6) beta >= 0,
  // with beta mapped from the restitution asked so that the clamped law gives it back.
  double damp = 0.0;
  double tangential_ratio = 0.0;  // sqrt(S_t / S_n) = sqrt(4 G* / E*)
  // thesis: zeta_n, zeta_t (T22, T23)
  double zeta_n = 0.0;
  double zeta_t = 0.0;
  // linear: k_n = kn_const + kn_per_radius R*, c_n = 2 gamma sqrt(k_n m*), k_t = 2/7 k_n
  double kn_const = 0.0;
  double kn_per_radius = 0.0;
  double gamma_linear = 0.0;
};

class PairTable {
 public:
  PairTable() = default;
  PairTable(const Scene& scene);
  const PairCoeffs& operator()(int a, int b) const { return table_[a * n_ + b]; }
  int n_materials() const { return n_; }
  const PairCoeffs* data() const { return table_.data(); }  // [a * n_materials() + b]

 private:
  int n_ = 0;
  std::vector<PairCoeffs> table_;
};

// Damping factor beta (<= 0) of the hertz-mindlin law (force clamped at zero) that gives the
// restitution e (0 < e <= 1); bisection on the integrated one-contact equation, accurate to 1e-6
// in e. restitution_hertz_clamped is its inverse (the e obtained for a given beta).
double hertz_beta_for_restitution(double e);
double restitution_hertz_clamped(double beta);
// The same for the linear spring-dashpot (damping ratio gamma >= 0, force clamped at zero).
double linear_gamma_for_restitution(double e);
double restitution_linear_clamped(double gamma);

}  // namespace dem2d
