// The superellipse's kernels (kernel_factory.hpp, make_superellipse_law_kernel): the
// Hertz-Mindlin law with each rolling model, as-seen stepper, no tracker.
#include "core/contact/kernel_factory.hpp"

namespace dem2d::kernels {

template std::unique_ptr<ContactKernel> make_superellipse_law_kernel<HertzMindlin>(
    const ContactSpec&, const PairTable&, RollingModelKind);

}  // namespace dem2d::kernels
