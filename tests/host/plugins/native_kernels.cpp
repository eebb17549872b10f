// A plugin built with nonsep_add_model's default kernels, KERNEL_SETS native: the widest set the building machine
// runs, alone (the baseline where it runs no wider set). test_host_kernels pins the baseline on it.
//   T(p) = cosh(p) - 1,  V(q) = q^2/2 + q^4/4
#include <cmath>
#include <nonsep/plugin_sdk.hpp>

struct NativeKernels {
  static constexpr std::size_t dimension = 1;
  template <class S>
  S T(nonsep::sdk::Vector<S> p) const {
    using std::cosh;
    return cosh(p[0]) - 1.0;
  }
  template <class S>
  S V(nonsep::sdk::Vector<S> q) const {
    const S square = q[0] * q[0];
    return square * (0.5 + 0.25 * square);
  }
};

NONSEP_EXPORT_MODEL(NativeKernels, "native_kernels", "0.1", "a plugin with the default kernels, KERNEL_SETS native",
                    "T = cosh(p) - 1, V = q^2/2 + q^4/4");
