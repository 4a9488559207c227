// PairTable: the mixed properties of every ordered pair of materials, computed once.
//
// Effective moduli (docs/models.md, "Effective material values"):
//   1/E* = (1 - nu_i^2)/E_i + (1 - nu_j^2)/E_j
//   1/G* = 2 (2 - nu_i)(1 + nu_i)/E_i + 2 (2 - nu_j)(1 + nu_j)/E_j
// Restitution, friction and rolling friction of a pair come from its [[interaction]] entry or,
// coefficient by coefficient, from the mean of the two materials' values.
#pragma once

#include <vector>

#include "core/base/scene.hpp"

namespace dem2d {

// The mixed properties of one ordered pair of materials: what every contact law builds its own
// coefficients from (contact_models.hpp, `Law::coeffs`). A law that needs a material property
// not mixed here reads it from the two materials `a` and `b`, e.g.
// mean(&MaterialSpec::normal_stiffness).
struct MaterialPair {
  MaterialSpec a, b;
  double mean(double MaterialSpec::*property) const { return 0.5 * (a.*property + b.*property); }
  double e_star = 0.0;       // Pa
  double g_star = 0.0;       // Pa
  double restitution = 1.0;  // asked (hertz-mindlin, linear)
  double mu_s = 0.0;         // sliding friction
  double mu_r = 0.0;         // rolling friction
  double zeta_n = 0.0;       // thesis: damping ratios (T22, T23)
  double zeta_t = 0.0;
};

class PairTable {
 public:
  PairTable() = default;
  PairTable(const Scene& scene);
  const MaterialPair& operator()(int a, int b) const { return table_[a * n_ + b]; }
  int n_materials() const { return n_; }

 private:
  int n_ = 0;
  std::vector<MaterialPair> table_;
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
