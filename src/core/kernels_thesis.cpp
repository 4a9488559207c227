// The thesis law's kernels (contact_kernel.hpp): every rolling model, tracker and
// stepper.
#include "core/contact_kernel.hpp"

namespace dem2d::kernels {

template std::unique_ptr<ContactKernel> make_law_kernel<ThesisModel>(const ContactSpec&,
                                                                     const PairTable&,
                                                                     RollingModelKind,
                                                                     IntegratorKind);

}  // namespace dem2d::kernels
