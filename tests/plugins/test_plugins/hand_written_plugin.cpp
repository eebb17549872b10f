// A plugin written by hand against plugin_abi.h (no SDK), compiled once per NONSEP_TEST_DEFECT to get a library
// that is wrong in exactly one way. Each defect has a test in test_loader_errors.cpp that asserts its message.
//   0  none: a valid plugin "hand_written" (T = p^2/2, V = q^2/2), so the defects below are the only difference
//   1  the exported symbol has another name
//   2  abi_version is 2 (a plugin built for the previous ABI, which had integrate())
//   3  struct_size is two pointers short (a table built against another header: neither of version 6's sizes)
//   4  the metadata is not valid JSON
//   5  the metadata names another plugin than the file
//   6  the required grad_V is null
//   7  the metadata claims hessian_T but the pointer is null
//   8  exports ABI version 1's entry function nonsep_plugin_entry instead of the symbol nonsep_plugin
//   9  the metadata lacks "thread_safe" (required since version 3)
//  10  the metadata claims d3T but the pointer is null
//  11  the table has d3V but the metadata does not claim it
//  12  exports the table itself under the symbol nonsep_plugin instead of a pointer to it (a common C mistake)
//  13  none: a valid plugin of ABI version 3 (its shorter table; the entries of version 4 past it are not read)
//  14  a separable part grad_U without value_U, which the energy of H needs
//  15  hvp_K without grad_K
//  16  none: a valid version-4 table that ends after chin_steps (before energy_TTV, energy_VVT), as first published
//  17  none: a valid version-4 table (before hvp_H of version 5)
//  18  the table has hvp_H but the metadata does not claim it
//  19  none: a valid version-5 table (before value_H and grad_H of version 6)
//  20  a model given by H ("hamiltonian_form": "general") without its required grad_H
//  21  a model given by H whose table still has grad_T and grad_V
//  22  a product-form model whose table has value_H and grad_H
//  23  none: a valid model given by H, H = (p^2 + q^2)/2
//  24  none: a valid version-6 table that ends before gauss_steps (the entries past it are not read)
#include <cstddef>
#include <cstring>

#include "nonsep/plugin_abi.h"
#include "support/plugin_table.hpp"

#ifndef NONSEP_TEST_DEFECT
#error "define NONSEP_TEST_DEFECT"
#endif
#ifndef NONSEP_TEST_NAME
#error "define NONSEP_TEST_NAME (the file stem)"
#endif

struct nonsep_instance {
  char last_error[64];
};

namespace {

nonsep_instance the_instance = {""};

#define METADATA_WITH(name, thread_safe, capabilities)                                     \
  "{\"name\": \"" name                                                                     \
  "\", \"version\": \"0.1\", \"description\": \"test plugin\", \"hamiltonian\": \"p q\", " \
  "\"dimension\": {\"fixed\": 1}, \"parameters\": [], " thread_safe "\"capabilities\": {" capabilities "}}"
#define METADATA_BODY(name, capabilities) METADATA_WITH(name, "\"thread_safe\": true, ", capabilities)

const char* metadata_json() {
#if NONSEP_TEST_DEFECT == 4
  return "{\"name\": \"" NONSEP_TEST_NAME "\", \"version\": ";
#elif NONSEP_TEST_DEFECT == 5
  return METADATA_BODY("someone_else", "");
#elif NONSEP_TEST_DEFECT == 7
  return METADATA_BODY(NONSEP_TEST_NAME, "\"hessian_T\": true");
#elif NONSEP_TEST_DEFECT == 9
  return METADATA_WITH(NONSEP_TEST_NAME, "", "");
#elif NONSEP_TEST_DEFECT == 10
  return METADATA_BODY(NONSEP_TEST_NAME, "\"d3T\": true, \"d3V\": false");
#elif NONSEP_TEST_DEFECT == 14
  return METADATA_BODY(NONSEP_TEST_NAME, "\"grad_U\": true");
#elif NONSEP_TEST_DEFECT == 15
  return METADATA_BODY(NONSEP_TEST_NAME, "\"hvp_K\": true");
#elif NONSEP_TEST_DEFECT == 20
  return METADATA_WITH(NONSEP_TEST_NAME, "\"hamiltonian_form\": \"general\", \"thread_safe\": true, ",
                       "\"value_H\": true");
#elif NONSEP_TEST_DEFECT == 21 || NONSEP_TEST_DEFECT == 23
  return METADATA_WITH(NONSEP_TEST_NAME, "\"hamiltonian_form\": \"general\", \"thread_safe\": true, ",
                       "\"value_H\": true, \"grad_H\": true");
#elif NONSEP_TEST_DEFECT == 22
  return METADATA_BODY(NONSEP_TEST_NAME, "\"value_H\": true, \"grad_H\": true");
#else
  return METADATA_BODY(NONSEP_TEST_NAME, "");
#endif
}

nonsep_status create(const char*, nonsep_instance** out, char*, size_t) {
  *out = &the_instance;
  return NONSEP_OK;
}
void destroy(nonsep_instance*) {}
size_t dimension(const nonsep_instance*) { return 1; }
nonsep_status identity(nonsep_instance*, const double* x, double* out, size_t count) {
  std::memcpy(out, x, count * sizeof(double));
  return NONSEP_OK;
}
#if NONSEP_TEST_DEFECT == 11 || NONSEP_TEST_DEFECT == 15
nonsep_status zero_third_derivative(nonsep_instance*, const double*, const double*, double* out, size_t count) {
  for (size_t b = 0; b < count; ++b) out[b] = 0.0;  // V = q^2/2 has no third derivative
  return NONSEP_OK;
}
#endif
const char* last_error(const nonsep_instance* instance) { return instance->last_error; }
#if NONSEP_TEST_DEFECT == 17 || NONSEP_TEST_DEFECT == 18
nonsep_status hvp_H_past_the_end(nonsep_instance*, uint32_t, const double*, const double*, const double*, const double*,
                                 double*, double*, size_t) {
  return NONSEP_INTERNAL_ERROR;
}
#endif
#if NONSEP_TEST_DEFECT >= 19 && NONSEP_TEST_DEFECT <= 23
// H = (p^2 + q^2)/2 (n = 1) and its gradient.
nonsep_status value_H(nonsep_instance*, const double* q, const double* p, double* out, size_t count) {
  for (size_t b = 0; b < count; ++b) out[b] = (p[b] * p[b] + q[b] * q[b]) / 2;
  return NONSEP_OK;
}
#endif
#if NONSEP_TEST_DEFECT >= 21 && NONSEP_TEST_DEFECT <= 23
nonsep_status grad_H(nonsep_instance*, const double* q, const double* p, double* dq, double* dp, size_t count) {
  std::memcpy(dq, q, count * sizeof(double));
  std::memcpy(dp, p, count * sizeof(double));
  return NONSEP_OK;
}
#endif
#if NONSEP_TEST_DEFECT == 24
nonsep_status gauss_steps_past_the_end(nonsep_instance*, const nonsep_gauss_steps_args*) {
  return NONSEP_INTERNAL_ERROR;
}
#endif
#if NONSEP_TEST_DEFECT == 16
nonsep_status energy_past_the_end(nonsep_instance*, const double*, const double*, double*, size_t) {
  return NONSEP_INTERNAL_ERROR;
}
#endif

nonsep_plugin_api make_table() {
  nonsep_plugin_api table =
      nonsep::testing::plugin_table(&metadata_json, &create, &destroy, &dimension, &identity, &identity, &last_error);
#if NONSEP_TEST_DEFECT == 2
  table.abi_version = 2u;
#elif NONSEP_TEST_DEFECT == 13
  table.abi_version = 3u;
  table.struct_size = static_cast<uint32_t>(NONSEP_PLUGIN_V3_STRUCT_SIZE);
  table.grad_K = &identity;  // past a version-3 table's end: never read
#elif NONSEP_TEST_DEFECT == 16
  table.abi_version = 4u;
  table.struct_size = static_cast<uint32_t>(NONSEP_PLUGIN_V4_KERNEL_STRUCT_SIZE);
  table.energy_TTV = &energy_past_the_end;  // past the shorter table's end: never read
#elif NONSEP_TEST_DEFECT == 17
  table.abi_version = 4u;
  table.struct_size = static_cast<uint32_t>(NONSEP_PLUGIN_V4_STRUCT_SIZE);
  table.hvp_H = &hvp_H_past_the_end;  // past a version-4 table's end: never read
#elif NONSEP_TEST_DEFECT == 3
  table.struct_size = static_cast<uint32_t>(sizeof(nonsep_plugin_api) - 2 * sizeof(void*));
#elif NONSEP_TEST_DEFECT == 6
  table.grad_V = nullptr;
#elif NONSEP_TEST_DEFECT == 11
  table.d3V = &zero_third_derivative;
#elif NONSEP_TEST_DEFECT == 14
  table.grad_U = &identity;
#elif NONSEP_TEST_DEFECT == 15
  table.hvp_K = &zero_third_derivative;  // a directional function of the same signature
#elif NONSEP_TEST_DEFECT == 18
  table.hvp_H = &hvp_H_past_the_end;
#elif NONSEP_TEST_DEFECT == 19
  table.abi_version = 5u;
  table.struct_size = static_cast<uint32_t>(NONSEP_PLUGIN_V5_STRUCT_SIZE);
  table.value_H = &value_H;  // past a version-5 table's end: never read
#elif NONSEP_TEST_DEFECT == 20
  table.grad_T = table.grad_V = nullptr;
  table.value_H = &value_H;
#elif NONSEP_TEST_DEFECT == 21 || NONSEP_TEST_DEFECT == 22
  table.value_H = &value_H;
  table.grad_H = &grad_H;
#elif NONSEP_TEST_DEFECT == 23
  table.grad_T = table.grad_V = nullptr;
  table.value_H = &value_H;
  table.grad_H = &grad_H;
#elif NONSEP_TEST_DEFECT == 24
  table.struct_size = static_cast<uint32_t>(NONSEP_PLUGIN_V6_EVALUATION_STRUCT_SIZE);
  table.gauss_steps = &gauss_steps_past_the_end;  // past the shorter table's end: never read
#endif
  return table;
}
const nonsep_plugin_api table = make_table();

}  // namespace

#if NONSEP_TEST_DEFECT == 1
extern "C" __attribute__((visibility("default"))) const nonsep_plugin_api* const nonsep_plugin_v0 = &table;
#elif NONSEP_TEST_DEFECT == 8
extern "C" __attribute__((visibility("default"))) const nonsep_plugin_api* nonsep_plugin_entry(void) { return &table; }
#elif NONSEP_TEST_DEFECT == 12
extern "C" __attribute__((visibility("default"))) const nonsep_plugin_api nonsep_plugin = table;
#else
NONSEP_DEFINE_PLUGIN(table);
#endif
