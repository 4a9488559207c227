#include "core/structure/fe_dynamics.hpp"

#include <stdexcept>

namespace dem2d {

FeDynamics::FeDynamics(const FeModel& model, double step, RayleighDamping damping)
    : model_(&model), h_(step), damping_(damping) {
  if (!(step > 0.0)) throw std::invalid_argument("FeDynamics: the step must be positive");
  k_ = model.reduced(model.stiffness());
  m_ = model.reduced(model.mass());
  c_ = damping_.mass * m_ + damping_.stiffness * k_;
  const FeSparse effective = k_ + (4.0 / (h_ * h_)) * m_ + (2.0 / h_) * c_;
  effective_.compute(effective);
  if (effective_.info() != Eigen::Success)
    throw std::runtime_error("FeDynamics: the effective stiffness could not be factorised");
  const auto n = k_.rows();
  u_ = v_ = a_ = f_ = FeVector::Zero(n);
}

void FeDynamics::start(const FeVector& u, const FeVector& v, const FeVector& f) {
  u_ = model_->restrict_free(u);
  v_ = model_->restrict_free(v);
  f_ = model_->restrict_free(f);
  Eigen::SimplicialLDLT<FeSparse> mass(m_);
  if (mass.info() != Eigen::Success)
    throw std::runtime_error("FeDynamics: the mass could not be factorised");
  a_ = mass.solve(f_ - c_ * v_ - k_ * u_);
  time_ = work_ = dissipated_ = 0.0;
}

void FeDynamics::step(const FeVector& f_next) {
  const FeVector f = model_->restrict_free(f_next);
  const double c0 = 4.0 / (h_ * h_), c1 = 4.0 / h_, c2 = 2.0 / h_;
  const FeVector rhs = f + m_ * (c0 * u_ + c1 * v_ + a_) + c_ * (c2 * u_ + v_);
  const FeVector u = effective_.solve(rhs);
  const FeVector a = c0 * (u - u_) - c1 * v_ - a_;
  const FeVector v = v_ + (0.5 * h_) * (a_ + a);
  const FeVector du = u - u_;
  work_ += 0.5 * du.dot(f_ + f);
  dissipated_ += 0.5 * (v_ + v).dot(c_ * du);
  u_ = u;
  v_ = v;
  a_ = a;
  f_ = f;
  time_ += h_;
}

double FeDynamics::kinetic_energy() const { return 0.5 * v_.dot(m_ * v_); }
double FeDynamics::strain_energy() const { return 0.5 * u_.dot(k_ * u_); }

}  // namespace dem2d
