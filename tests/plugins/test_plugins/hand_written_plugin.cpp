// A plugin written by hand against plugin_abi.h (no SDK), compiled once per NONSEP_TEST_DEFECT to get a library
// that is wrong in exactly one way. Each defect has a test in test_loader_errors.cpp that asserts its message.
//   0  none: a valid plugin "hand_written" (T = p^2/2, V = q^2/2), so the defects below are the only difference
//   1  the exported symbol has another name
//   2  abi_version is 1 (a plugin built for the previous ABI, without integrate)
//   3  struct_size is one pointer short (a table built against a shorter header: version 1's size)
//   4  the metadata is not valid JSON
//   5  the metadata names another plugin than the file
//   6  the required grad_V is null
//   7  the metadata claims hessian_T but the pointer is null
//   8  exports ABI version 1's entry function nonsep_plugin_entry instead of the symbol nonsep_plugin
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

#define METADATA_BODY(name, capabilities)                                                                      \
  "{\"name\": \"" name "\", \"version\": \"0.1\", \"description\": \"test plugin\", \"hamiltonian\": \"p q\", " \
  "\"dimension\": {\"fixed\": 1}, \"parameters\": [], \"capabilities\": {" capabilities "}}"

const char* metadata_json() {
#if NONSEP_TEST_DEFECT == 4
  return "{\"name\": \"" NONSEP_TEST_NAME "\", \"version\": ";
#elif NONSEP_TEST_DEFECT == 5
  return METADATA_BODY("someone_else", "");
#elif NONSEP_TEST_DEFECT == 7
  return METADATA_BODY(NONSEP_TEST_NAME, "\"hessian_T\": true");
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
const char* last_error(const nonsep_instance* instance) { return instance->last_error; }


const nonsep_plugin_api table = {
#if NONSEP_TEST_DEFECT == 2
    1u,
#else
    NONSEP_PLUGIN_ABI_VERSION,
#endif
#if NONSEP_TEST_DEFECT == 3
    static_cast<uint32_t>(sizeof(nonsep_plugin_api) - sizeof(void*)),
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
    nullptr,  // integrate: optional, absent (the host steps through grad_T and grad_V)
};

}  // namespace

#if NONSEP_TEST_DEFECT == 1
extern "C" __attribute__((visibility("default"))) const nonsep_plugin_api* const nonsep_plugin_v0 = &table;
#elif NONSEP_TEST_DEFECT == 8
extern "C" __attribute__((visibility("default"))) const nonsep_plugin_api* nonsep_plugin_entry(void) { return &table; }
#else
NONSEP_DEFINE_PLUGIN(table);
#endif
