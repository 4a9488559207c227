// The laws of an ore breakage, as plain functions of numbers (docs/models.md, "Grinding"):
// who takes how much of a contact's energy, how likely a loading breaks a particle, and what
// the fragments are. core/mill/grinding.cpp applies them to the particles.
#pragma once

#include <cstdint>
#include <vector>

namespace dem2d {

// A material's compliance (1 - nu^2) / E (1/Pa): in a Hertz contact each surface moves in
// proportion to it, so each body stores that share of the contact's strain energy.
inline double compliance(double youngs_modulus, double poisson_ratio) {
  return (1.0 - poisson_ratio * poisson_ratio) / youngs_modulus;
}
// The share of body a against body b.
inline double energy_share(double compliance_a, double compliance_b) {
  return compliance_a / (compliance_a + compliance_b);
}

// Vogel and Peukert's breakage probability of one loading of specific energy w (J/kg) on a
// particle of diameter d (m): 1 - exp(-f_mat d (w - xw_min / d)), 0 below the threshold.
// Over k equal loadings the survivals multiply: 1 - exp(-f_mat d k (w - w_min)), their form.
double vogel_peukert_probability(double f_mat, double xw_min, double diameter, double w);

// The breakage index t10 (a fraction: the progeny's mass passing a tenth of the parent's size)
// of a loading of specific energy e_cs (kWh/t): A (1 - exp(-b e_cs)) / 100.
double t10_fraction(double a_percent, double b, double e_cs_kwh_per_t);
// The exponent alpha of the progeny's passing (x / X)^alpha with t10 = (1/10)^alpha.
double progeny_exponent(double t10);

// The progeny of a parent of diameter X and mass M (density rho) with passing (x / X)^alpha:
// spheres down to fines_diameter, coarsest first, then the fines as one mass. The classes of
// diameter X 2^(-k/4) are filled from the top: each takes as many spheres of its geometric-mean
// diameter as its mass (plus what the class above left over) holds; the rest below the last
// class is fines. The radii's masses plus fines_mass equal M to round-off.
struct Progeny {
  std::vector<double> radii;
  double fines_mass = 0.0;
  double fines_law_mass = 0.0;  // the part of fines_mass the law puts below fines_diameter
  double alpha = 0.0;
};
inline constexpr int kMaxFragments = 256;  // per break; the rest of the mass goes to the fines
Progeny t10_progeny(double parent_radius, double density, double alpha, double fines_diameter);

// Where the fragments of one break sit: offsets from the parent's centre for radii sorted from
// the largest (a sunflower spiral inside the parent's circle, turned by `turn`), moved so that
// their mass centre is the parent's centre, and drawn in so that their moment of inertia about
// it (sum m |o|^2 + 2/5 m r^2) stays within the parent's 2/5 M R^2: momentum is kept and the
// kinetic energy of the parent's rigid motion does not grow.
struct Offset {
  double x, y;
};
std::vector<Offset> fragment_offsets(double parent_radius, const std::vector<double>& radii,
                                     double turn);

}  // namespace dem2d
