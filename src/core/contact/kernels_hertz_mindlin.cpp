// The hertz-mindlin law's kernels (kernel_factory.hpp): every rolling model, tracker and
// stepper.
#include "core/contact/kernel_factory.hpp"

namespace dem2d::kernels {

template std::unique_ptr<ContactKernel> make_law_kernel<HertzMindlin>(const ContactSpec&,
                                                                      const PairTable&,
                                                                      RollingModelKind,
                                                                      IntegratorKind);

}  // namespace dem2d::kernels
