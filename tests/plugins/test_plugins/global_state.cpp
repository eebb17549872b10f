// A plugin with global mutable state, written against plugin_abi.h (no SDK): T = p^2/2 and V = c q^4/4, where the
// coupling c is kept in a global that every create() overwrites (the k-th instance created sets c = k), as a model
// that stores per-instance data in a global does. Two instances therefore disturb each other, whatever the threads.
// Compiled twice:
//   GLOBAL_STATE_DECLARES_SAFE 0  "global_state": declares "thread_safe": false (honest; the host must use one
//                                 instance on one thread, and `nonsep inspect --check` skips its two-thread check)
//   GLOBAL_STATE_DECLARES_SAFE 1  "global_state_claims_safe": declares true; the two-thread check must catch it.
#include <cstddef>

#include "nonsep/plugin_abi.h"
#include "support/plugin_table.hpp"

#ifndef GLOBAL_STATE_DECLARES_SAFE
#error "define GLOBAL_STATE_DECLARES_SAFE"
#endif

struct nonsep_instance {
  char last_error[1];
};

namespace {

double coupling = 0.0;  // the global state: the number of instances created so far
int created = 0;

const char* metadata_json() {
#if GLOBAL_STATE_DECLARES_SAFE
  return "{\"name\": \"global_state_claims_safe\", \"version\": \"0.1\", \"description\": \"test plugin\", "
         "\"hamiltonian\": \"T = p^2/2, V = c q^4/4, c global\", \"dimension\": {\"fixed\": 1}, \"parameters\": [], "
         "\"thread_safe\": true, \"capabilities\": {}}";
#else
  return "{\"name\": \"global_state\", \"version\": \"0.1\", \"description\": \"test plugin\", "
         "\"hamiltonian\": \"T = p^2/2, V = c q^4/4, c global\", \"dimension\": {\"fixed\": 1}, \"parameters\": [], "
         "\"thread_safe\": false, \"capabilities\": {}}";
#endif
}

nonsep_status create(const char*, nonsep_instance** out, char*, size_t) {
  coupling = ++created;
  *out = new nonsep_instance{{'\0'}};
  return NONSEP_OK;
}
void destroy(nonsep_instance* instance) { delete instance; }
size_t dimension(const nonsep_instance*) { return 1; }
nonsep_status grad_T(nonsep_instance*, const double* p, double* out, size_t count) {
  for (size_t b = 0; b < count; ++b) out[b] = p[b];
  return NONSEP_OK;
}
nonsep_status grad_V(nonsep_instance*, const double* q, double* out, size_t count) {
  for (size_t b = 0; b < count; ++b) out[b] = coupling * q[b] * q[b] * q[b];
  return NONSEP_OK;
}
const char* last_error(const nonsep_instance* instance) { return instance->last_error; }

const nonsep_plugin_api table =
    nonsep::testing::plugin_table(&metadata_json, &create, &destroy, &dimension, &grad_T, &grad_V, &last_error);

}  // namespace

NONSEP_DEFINE_PLUGIN(table);
