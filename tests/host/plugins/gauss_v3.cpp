// paper2d with the kernels of the baseline and x86-64-v3 alone (the build gives it the baseline; this file adds the
// v3 set before the SDK sees the setting): the Gauss-Legendre kernel's x86-64-v3 copy, which a processor that runs
// x86-64-v4 would not take from a plugin that also has the v4 set. test_host_kernels runs it against the evaluation
// path byte for byte.
#undef NONSEP_SDK_WIDE_KERNEL_SETS
#define NONSEP_SDK_WIDE_KERNEL_SETS 1
#include "paper2d/paper2d.hpp"

NONSEP_EXPORT_MODEL(Paper2D, "gauss_v3", "1.0.0", "paper2d with the baseline and x86-64-v3 kernels alone (test)",
                    "T = p1 + p2 + (p1^3 + p2^3)/6, V = |q|^2/2 + |q|^4/12 + coupling q1^2 q2^2");
