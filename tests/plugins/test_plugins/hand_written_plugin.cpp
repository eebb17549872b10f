// A plugin written by hand against plugin_abi.h (no SDK), compiled once per NONSEP_TEST_DEFECT to get a library
// that is wrong in exactly one way. Each defect has a test in test_loader_errors.cpp that asserts its message.
//   0  none: a valid plugin "hand_written" (T = p^2/2, V = q^2/2), so the defects below are the only difference
//   1  the exported symbol has another name
//   2  abi_version is 2 (a plugin built for the previous ABI, which had integrate())
//   3  struct_size is one pointer short (a table built against a shorter header: version 2's size)
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
#include <cstddef>
#include <cstring>

#include "nonsep/plugin_abi.h"

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
#if NONSEP_TEST_DEFECT == 16
nonsep_status energy_past_the_end(nonsep_instance*, const double*, const double*, double*, size_t) {
  return NONSEP_INTERNAL_ERROR;
}
#endif

const nonsep_plugin_api table = {
#if NONSEP_TEST_DEFECT == 2
    2u,
#elif NONSEP_TEST_DEFECT == 13
    3u,
#else
    NONSEP_PLUGIN_ABI_VERSION,
#endif
#if NONSEP_TEST_DEFECT == 3
    static_cast<uint32_t>(sizeof(nonsep_plugin_api) - sizeof(void*)),
#elif NONSEP_TEST_DEFECT == 13
    static_cast<uint32_t>(NONSEP_PLUGIN_V3_STRUCT_SIZE),
#elif NONSEP_TEST_DEFECT == 16
    static_cast<uint32_t>(NONSEP_PLUGIN_V4_KERNEL_STRUCT_SIZE),
#else
    static_cast<uint32_t>(sizeof(nonsep_plugin_api)),
#endif
    &metadata_json,
    &create,
    &destroy,
    &dimension,
    &identity,
#if NONSEP_TEST_DEFECT == 6
    nullptr,
#else
    &identity,
#endif
    nullptr,
    nullptr,
    nullptr,
    nullptr,
    &last_error,
    nullptr,  // d3T: optional, absent
#if NONSEP_TEST_DEFECT == 11
    &zero_third_derivative,
#else
    nullptr,  // d3V: optional, absent
#endif
#if NONSEP_TEST_DEFECT == 13
    &identity,  // past a version-3 table's end: never read
#else
    nullptr,  // grad_K
#endif
#if NONSEP_TEST_DEFECT == 14
    &identity,
#else
    nullptr,  // grad_U
#endif
    nullptr,  // value_K
    nullptr,  // value_U
    nullptr,  // hessian_K
    nullptr,  // hessian_U
    nullptr,  // hvp_T
    nullptr,  // hvp_V
#if NONSEP_TEST_DEFECT == 15
    &zero_third_derivative,  // a directional function of the same signature
#else
    nullptr,  // hvp_K
#endif
    nullptr,  // hvp_U
    nullptr,  // chin_steps
#if NONSEP_TEST_DEFECT == 16
    &energy_past_the_end,  // past the shorter table's end: never read
#else
    nullptr,  // energy_TTV
#endif
    nullptr,  // energy_VVT
};

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
