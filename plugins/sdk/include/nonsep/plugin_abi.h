/* nonsep plugin ABI, version 3. The boundary evaluates; it does not integrate: the host owns every stepper and
 * crosses the boundary once per batch of states for a gradient (or a Hessian, a value, a third derivative).
 * Version 2 had a fused stepping function integrate() (the plugin ran the core's integrator itself); version 1
 * exported a function, nonsep_plugin_entry, returning the table instead of the pointer below. Plugins of either
 * are refused: rebuild them against the installed SDK.
 *
 * A plugin is a shared library that exports one C symbol, NONSEP_PLUGIN_SYMBOL ("nonsep_plugin"): a constant
 * pointer to a constant, statically allocated function table (nonsep_plugin_api) that stays valid while the
 * library is loaded. NONSEP_DEFINE_PLUGIN(table) defines it, in C or C++. The host reads it with Boost.DLL's
 * import_alias, which keeps the library loaded for as long as the host holds the table. Nothing else is looked
 * up by name.
 *
 * Checks the host makes, in this order, before using anything else in the table:
 *   0. the symbol holds an aligned address inside a loaded library (refused otherwise: a library that exports
 *      the table itself under the name, instead of a pointer to it)
 *   1. abi_version == NONSEP_PLUGIN_ABI_VERSION   (refused with "expected 3, found N")
 *   2. struct_size == sizeof(nonsep_plugin_api)  (refused with expected and found sizes)
 *   3. the required functions are non-null        (metadata_json, create, destroy, dimension, grad_T, grad_V,
 *                                                   last_error)
 *   4. metadata_json() returns valid JSON of the shape below, whose capabilities match the table.
 *
 * Batch layout (same as nonsep/core/model.hpp): `count` states of dimension n, state-major and contiguous.
 * Component i of state b is at x[b*n + i]; gradient outputs have the same layout; Hessian outputs hold count
 * row-major n x n matrices, entry (i, j) of state b at out[b*n*n + i*n + j]. Value outputs hold one double
 * per state. Third-derivative inputs u (one direction per state) and outputs have the gradient layout.
 * Input and output arrays never overlap. The host crosses this boundary once per batch.
 *
 * Errors: every function that can fail returns a nonsep_status and never lets a C++ exception (or a longjmp)
 * escape. After a status other than NONSEP_OK, last_error(instance) returns a NUL-terminated message that
 * stays valid until the next call on that instance. create() writes its message into the caller's buffer.
 * Non-finite results are numbers, not failures: the host reports the state as diverged.
 *
 * Thread safety: metadata_json() may be called from any thread at any time. One instance is used by one thread
 * at a time. With "thread_safe": true in the metadata, create() may be called concurrently and distinct
 * instances are fully independent (no mutable state shared between them: no globals, no static caches), so a
 * multi-threaded host creates one instance per thread. With "thread_safe": false the host uses a single
 * instance on a single thread for the whole run: a plugin with global mutable state (a library that is not
 * reentrant, a shared cache, per-model data kept in a global) must say false.
 *
 * Metadata JSON (metadata_json()), a static string:
 *   {
 *     "name": "paper1d", "version": "1.0.0", "description": "...",
 *     "hamiltonian": "what T, V and H_TTV / H_VVT are, in words",
 *     "dimension": { "fixed": 1 }                  or  { "parameter": "dimension" },
 *     "parameters": [ { "name": "dimension", "type": "integer" | "number" | "boolean",
 *                       "default": 2, "minimum": 1, "maximum": 64, "unit": "", "description": "..." } ],
 *     "thread_safe": true,
 *     "capabilities": { "value_T": true, "value_V": true, "hessian_T": true, "hessian_V": true,
 *                       "d3T": true, "d3V": true }
 *   }
 * "minimum", "maximum" and "unit" may be absent; "thread_safe" is required. Each capability is true exactly
 * when the table's pointer is non-null (an absent capability counts as false).
 */
#ifndef NONSEP_PLUGIN_ABI_H
#define NONSEP_PLUGIN_ABI_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define NONSEP_PLUGIN_ABI_VERSION 3u
#define NONSEP_PLUGIN_SYMBOL "nonsep_plugin"
/* The symbol of ABI version 1 (a function returning the table); the host names it when refusing such a plugin. */
#define NONSEP_PLUGIN_V1_ENTRY_SYMBOL "nonsep_plugin_entry"

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

  /* Optional (NULL when absent): directional third derivatives, which with the Hessians give the gradient of
   * the solved H (TTV: dH/dp = 2 T'' V'' T', dH/dq = d3V(q, T'(p)); VVT with the roles of T and V swapped).
   * u holds one direction per state (count*n, the gradient layout); out[b*n + k] = sum_ij T_ijk(p_b) u_bi u_bj,
   * and d3V the same in q. */
  nonsep_status (*d3T)(nonsep_instance* instance, const double* p, const double* u, double* out, size_t count);
  nonsep_status (*d3V)(nonsep_instance* instance, const double* q, const double* u, double* out, size_t count);
} nonsep_plugin_api;

#ifdef __cplusplus
}
#define NONSEP_PLUGIN_EXTERN_C extern "C"
#else
#define NONSEP_PLUGIN_EXTERN_C
#endif

/* Defines the exported symbol NONSEP_PLUGIN_SYMBOL, pointing at `table` (a nonsep_plugin_api with static storage),
 * with default visibility whatever -fvisibility says. Use it once per plugin, at file scope:
 *   static const nonsep_plugin_api table = { NONSEP_PLUGIN_ABI_VERSION, sizeof(nonsep_plugin_api), ... };
 *   NONSEP_DEFINE_PLUGIN(table); */
#define NONSEP_DEFINE_PLUGIN(table) \
  NONSEP_PLUGIN_EXTERN_C __attribute__((visibility("default"))) const nonsep_plugin_api* const nonsep_plugin = &(table)

#endif /* NONSEP_PLUGIN_ABI_H */
