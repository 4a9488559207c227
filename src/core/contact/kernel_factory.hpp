// The kernels of one contact law: its rolling models, trackers and steppers, instantiated by
// kernels_<law>.cpp (contact_kernel.hpp and the three files of its members).
#pragma once

#include <memory>
#include <tuple>
#include <type_traits>

#include "core/contact/kernel_pairs.hpp"
#include "core/contact/kernel_release.hpp"
#include "core/contact/kernel_walls.hpp"
#include "core/shape/superellipse_shape.hpp"

namespace dem2d::kernels {

// The stepper follows the integrator (contact_models.hpp, Steppers).
template <class Law, class Rolling, class Tracker>
std::unique_ptr<ContactKernel> make_kernel(const ContactSpec& spec, const PairTable& table,
                                           IntegratorKind integrator) {
  if (integrator == IntegratorKind::kIterative)
    return std::make_unique<Kernel<ContactModel<Law, Rolling, Tracker, StepTrapezoid>>>(spec,
                                                                                        table);
  return std::make_unique<Kernel<ContactModel<Law, Rolling, Tracker, StepAsSeen>>>(spec, table);
}

// The entry of a registry (a std::tuple of models) whose kKind is `kind`, handed to f as
// std::type_identity<Model>.
template <class Registry, class Kind, class F>
std::unique_ptr<ContactKernel> pick(Kind kind, F f) {
  return [&]<class... Models>(std::type_identity<std::tuple<Models...>>) {
    std::unique_ptr<ContactKernel> out;
    static_cast<void>(
        ((Models::kKind == kind ? (out = f(std::type_identity<Models>{}), true) : false) || ...));
    return out;
  }(std::type_identity<Registry>{});
}

// Every kernel of one law: its rolling models, trackers and steppers (rolling_kind: the one the
// scene runs, none when no pair has rolling friction).
template <class Law>
std::unique_ptr<ContactKernel> make_law_kernel(const ContactSpec& spec, const PairTable& table,
                                               RollingModelKind rolling_kind,
                                               IntegratorKind integrator) {
  return pick<RollingModels>(rolling_kind, [&](auto rolling) -> std::unique_ptr<ContactKernel> {
    using Rolling = typename decltype(rolling)::type;
    if (spec.track_breakage)
      return make_kernel<Law, Rolling, TrackBreakage>(spec, table, integrator);
    if (spec.track_peak_energy)
      return make_kernel<Law, Rolling, TrackPeakEnergy>(spec, table, integrator);
    return make_kernel<Law, Rolling, TrackNone>(spec, table, integrator);
  });
}

}  // namespace dem2d::kernels

namespace dem2d::kernels {

// The superellipse's kernels (core/shape/superellipse_shape.hpp): one law's rolling models and
// trackers with the as-seen stepper. Each is a scalar narrow phase of its own, so only the
// Hertz-Mindlin law is instantiated (kernels_superellipse.cpp); the iterative integrator is
// refused (make_contact_kernel).
template <class Law>
std::unique_ptr<ContactKernel> make_superellipse_law_kernel(const ContactSpec& spec,
                                                            const PairTable& table,
                                                            RollingModelKind rolling_kind) {
  return pick<RollingModels>(rolling_kind, [&](auto rolling) -> std::unique_ptr<ContactKernel> {
    using Rolling = typename decltype(rolling)::type;
    if (spec.track_breakage)
      return std::make_unique<
          Kernel<ContactModel<Law, Rolling, TrackBreakage, StepAsSeen>, SuperEllipseShape>>(spec,
                                                                                            table);
    if (spec.track_peak_energy)
      return std::make_unique<
          Kernel<ContactModel<Law, Rolling, TrackPeakEnergy, StepAsSeen>, SuperEllipseShape>>(
          spec, table);
    return std::make_unique<
        Kernel<ContactModel<Law, Rolling, TrackNone, StepAsSeen>, SuperEllipseShape>>(spec, table);
  });
}

}  // namespace dem2d::kernels
