// paper1d written against plugin_abi.h alone: no SDK, no checks, no exceptions, gradients only. The least a plugin
// can do per call, so that bench/abi_floor.hpp measures what the evaluation-only boundary itself costs, not what the
// SDK or the host add. The host can load it too (nonsep run with "plugin": "<path>/paper1d_minimal.so"), though
// without Hessians it reports no energies.
//
// Gradients as in plugins/paper1d/paper1d.hpp and bench/hand_written.hpp, the same operations in the same order
// (T' = 1 + 0.5 p p, V' = q (1 + q q / 3)), so that every loop built on them gives the same bits.
//
// Not part of the ABI: paper1d_minimal_grad_T_scalar and paper1d_minimal_grad_V_scalar, the same gradients of one
// number taken and returned by value (in registers), for the benchmark's control that tells the cost of a call from
// the cost of passing numbers through memory.
#include <cstddef>

#include "nonsep/plugin_abi.h"

struct nonsep_instance {
  int unused;
};

namespace {

nonsep_instance the_instance{0};

const char* metadata_json() {
  return "{\"name\": \"paper1d_minimal\", \"version\": \"1.0.0\", \"description\": \"paper1d against plugin_abi.h "
         "alone (benchmark floor)\", \"hamiltonian\": \"T = p + p^3/6, V = q^2/2 + q^4/12\", \"dimension\": "
         "{\"fixed\": 1}, \"parameters\": [], \"thread_safe\": true, \"capabilities\": {}}";
}
nonsep_status create(const char*, nonsep_instance** out, char*, std::size_t) {
  *out = &the_instance;
  return NONSEP_OK;
}
void destroy(nonsep_instance*) {}
std::size_t dimension(const nonsep_instance*) { return 1; }
nonsep_status grad_T(nonsep_instance*, const double* p, double* out, std::size_t count) {
  for (std::size_t b = 0; b < count; ++b) out[b] = 1.0 + 0.5 * p[b] * p[b];
  return NONSEP_OK;
}
nonsep_status grad_V(nonsep_instance*, const double* q, double* out, std::size_t count) {
  for (std::size_t b = 0; b < count; ++b) out[b] = q[b] * (1.0 + q[b] * q[b] / 3.0);
  return NONSEP_OK;
}
const char* last_error(const nonsep_instance*) { return ""; }

const nonsep_plugin_api table = {
    NONSEP_PLUGIN_ABI_VERSION,
    static_cast<uint32_t>(sizeof(nonsep_plugin_api)),
    &metadata_json,
    &create,
    &destroy,
    &dimension,
    &grad_T,
    &grad_V,
    nullptr,  // value_T
    nullptr,  // value_V
    nullptr,  // hessian_T
    nullptr,  // hessian_V
    &last_error,
    nullptr,  // d3T
    nullptr,  // d3V
    nullptr,  // grad_K
    nullptr,  // grad_U
    nullptr,  // value_K
    nullptr,  // value_U
    nullptr,  // hessian_K
    nullptr,  // hessian_U
    nullptr,  // hvp_T
    nullptr,  // hvp_V
    nullptr,  // hvp_K
    nullptr,  // hvp_U
    nullptr,  // chin_steps
    nullptr,  // energy_TTV
    nullptr,  // energy_VVT
    nullptr,  // hvp_H
    nullptr,  // chin_tangent_steps
};

}  // namespace

NONSEP_DEFINE_PLUGIN(table);

extern "C" __attribute__((visibility("default"))) double paper1d_minimal_grad_T_scalar(double p) {
  return 1.0 + 0.5 * p * p;
}
extern "C" __attribute__((visibility("default"))) double paper1d_minimal_grad_V_scalar(double q) {
  return q * (1.0 + q * q / 3.0);
}
