/* nonsep plugin ABI, version 1.
 *
 * A plugin is a shared library that exports one C symbol, NONSEP_PLUGIN_ENTRY_SYMBOL ("nonsep_plugin_entry"),
 * of type nonsep_plugin_entry_fn. It returns a pointer to a constant, statically allocated function table
 * (nonsep_plugin_api) that stays valid while the library is loaded. Nothing else is looked up by name.
 *
 * Checks the host makes, in this order, before using anything else in the table:
 *   1. abi_version == NONSEP_PLUGIN_ABI_VERSION   (refused with "expected 1, found N")
 *   2. struct_size == sizeof(nonsep_plugin_api)  (refused with expected and found sizes)
 *   3. metadata_json() returns valid JSON of the shape below.
 *
 * Batch layout (same as nonsep/core/model.hpp): `count` states of dimension n, state-major and contiguous.
 * Component i of state b is at x[b*n + i]; gradient outputs have the same layout; Hessian outputs hold count
 * row-major n x n matrices, entry (i, j) of state b at out[b*n*n + i*n + j]. Value outputs hold one double
 * per state. Input and output arrays never overlap. The host crosses this boundary once per batch.
 *
 * Errors: every function that can fail returns a nonsep_status and never lets a C++ exception (or a longjmp)
 * escape. After a status other than NONSEP_OK, last_error(instance) returns a NUL-terminated message that
 * stays valid until the next call on that instance. create() writes its message into the caller's buffer.
 *
 * Thread safety: metadata_json() and create() may be called from any thread at any time. One instance may be
 * used by one thread at a time; distinct instances are fully independent, so a multi-threaded host creates
 * one instance per thread.
 *
 * Metadata JSON (metadata_json()), a static string:
 *   {
 *     "name": "paper1d", "version": "1.0.0", "description": "...",
 *     "hamiltonian": "what T, V and H_TTV / H_VVT are, in words",
 *     "dimension": { "fixed": 1 }                  or  { "parameter": "dimension" },
 *     "parameters": [ { "name": "dimension", "type": "integer" | "number" | "boolean",
 *                       "default": 2, "minimum": 1, "maximum": 64, "unit": "", "description": "..." } ],
 *     "capabilities": { "value_T": true, "value_V": true, "hessian_T": true, "hessian_V": true }
 *   }
 * "minimum", "maximum" and "unit" may be absent. Each capability is true exactly when the table's pointer is
 * non-null.
 */
#ifndef NONSEP_PLUGIN_ABI_H
#define NONSEP_PLUGIN_ABI_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define NONSEP_PLUGIN_ABI_VERSION 1u
#define NONSEP_PLUGIN_ENTRY_SYMBOL "nonsep_plugin_entry"

typedef enum nonsep_status {
  NONSEP_OK = 0,
  NONSEP_INVALID_PARAMETERS = 1, /* create(): a parameter is unknown, of the wrong type or out of range */
  NONSEP_EVALUATION_FAILED = 2,  /* the model could not evaluate (domain error, non-finite result, ...) */
  NONSEP_INTERNAL_ERROR = 3,     /* an exception or other unexpected failure inside the plugin */
  NONSEP_UNSUPPORTED = 4         /* the requested optional function is not provided */
} nonsep_status;

typedef struct nonsep_instance nonsep_instance; /* opaque, owned by the plugin */

typedef struct nonsep_plugin_api {
  uint32_t abi_version; /* NONSEP_PLUGIN_ABI_VERSION */
  uint32_t struct_size; /* sizeof(nonsep_plugin_api) */

  /* Static metadata, valid while the library is loaded. Never NULL. */
  const char* (*metadata_json)(void);

  /* Creates an instance from a JSON object of parameters ("{}" for all defaults). On failure returns a status,
   * leaves *out NULL and writes a message naming the parameter into message[0 .. message_size-1]. */
  nonsep_status (*create)(const char* parameters_json, nonsep_instance** out, char* message, size_t message_size);
  void (*destroy)(nonsep_instance* instance);

  /* Number of degrees of freedom n of this instance (> 0). */
  size_t (*dimension)(const nonsep_instance* instance);

  /* Required: grad T at count momenta, grad V at count positions. */
  nonsep_status (*grad_T)(nonsep_instance* instance, const double* p, double* out, size_t count);
  nonsep_status (*grad_V)(nonsep_instance* instance, const double* q, double* out, size_t count);

  /* Optional (NULL when absent): values of T and V, and their Hessians (needed for the energy). */
  nonsep_status (*value_T)(nonsep_instance* instance, const double* p, double* out, size_t count);
  nonsep_status (*value_V)(nonsep_instance* instance, const double* q, double* out, size_t count);
  nonsep_status (*hessian_T)(nonsep_instance* instance, const double* p, double* out, size_t count);
  nonsep_status (*hessian_V)(nonsep_instance* instance, const double* q, double* out, size_t count);

  /* Message for the last failed call on this instance (never NULL; "" when there was none). */
  const char* (*last_error)(const nonsep_instance* instance);
} nonsep_plugin_api;

typedef const nonsep_plugin_api* (*nonsep_plugin_entry_fn)(void);

#ifdef __cplusplus
}
#endif

#endif /* NONSEP_PLUGIN_ABI_H */
