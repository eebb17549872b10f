/* nonsep plugin ABI, version 2 (version 1 had no integrate(), and exported a function, nonsep_plugin_entry,
 * returning the table instead of the pointer below).
 *
 * A plugin is a shared library that exports one C symbol, NONSEP_PLUGIN_SYMBOL ("nonsep_plugin"): a constant
 * pointer to a constant, statically allocated function table (nonsep_plugin_api) that stays valid while the
 * library is loaded. NONSEP_DEFINE_PLUGIN(table) defines it, in C or C++. The host reads it with Boost.DLL's
 * import_alias, which keeps the library loaded for as long as the host holds the table. Nothing else is looked
 * up by name.
 *
 * Checks the host makes, in this order, before using anything else in the table:
 *   1. abi_version == NONSEP_PLUGIN_ABI_VERSION   (refused with "expected 2, found N")
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
 *     "capabilities": { "value_T": true, "value_V": true, "hessian_T": true, "hessian_V": true,
 *                       "integrate": true }
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

#define NONSEP_PLUGIN_ABI_VERSION 2u
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

/* The integrator integrate() runs: the same choices as a job's "integrator" object (nonsep/core/integrator.hpp).
 * A plain struct, so the hot path parses nothing. */
typedef enum nonsep_scheme {
  NONSEP_SCHEME_BASIC = 0,   /* Chin's basic step, order 2/3 */
  NONSEP_SCHEME_TRIPLET = 1, /* triplet composition of the basic step */
  NONSEP_SCHEME_MPE = 2      /* multi-product expansion of the basic step */
} nonsep_scheme;

typedef enum nonsep_form {
  NONSEP_FORM_TTV = 0, /* H = T_i V_ij T_j */
  NONSEP_FORM_VVT = 1  /* H = V_i T_ij V_j */
} nonsep_form;

typedef struct nonsep_integrator {
  uint32_t scheme;           /* a nonsep_scheme */
  uint32_t form;             /* a nonsep_form */
  int64_t order_numerator;   /* the order as a fraction: 2/3, 4/3, 2/1, ... */
  int64_t order_denominator; /* > 0 */
  double t2;                 /* the basic step's free coefficient (finite, non-zero; default -6^(1/3)) */
} nonsep_integrator;

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

  /* Optional (NULL when absent; capability "integrate"): the fused stepping loop. Advances the count states
   * (q, p in the batch layout above, updated in place) by `steps` steps of size dt with `integrator`, run inside
   * the plugin on the model compiled into it (the SDK instantiates the core's Integrator on its ModelAdapter), so
   * no function pointer is crossed per gradient. It must give, bit for bit, the states and evaluation counts that
   * the core's Integrator stepping through this table's grad_T and grad_V gives: the host runs a chunk of steps
   * through it, and falls back to its own stepping (through grad_T, grad_V) to redo a chunk step by step.
   *
   * First-same-as-last cache: the basic step's last outer gradient (grad V at q in TTV, grad T at p in VVT) is
   * reused as the next step's first. fsal_gradient holds count*n doubles (batch layout). On entry, *fsal_valid
   * != 0 says that fsal_gradient holds that gradient at the states' current q (TTV) or p (VVT); 0 that it must
   * be evaluated. On return with NONSEP_OK, *fsal_valid and fsal_gradient describe the final states the same way
   * (0 when the integrator's last gradient is not at the final point, as after an MPE step). So a run split into
   * calls, or mixing calls with the host's own steps, makes exactly the evaluations of one uninterrupted run.
   *
   * Counts: on NONSEP_OK, adds the gradient evaluations made, per state (one batched gradient of count states
   * counts count), to *grad_T_count and *grad_V_count.
   *
   * steps == 0 changes nothing. A bad integrator (unknown scheme or form, an order the scheme does not have, a
   * bad t2 or dt) is NONSEP_INTERNAL_ERROR with a message. Non-finite numbers are not failures: the states are
   * advanced as computed and the host checks them. After a status other than NONSEP_OK, q, p, fsal_gradient,
   * *fsal_valid and the counts are unspecified (the host goes back to its own copy).
   *
   * Thread safety: as for the other functions of an instance (one thread at a time per instance); the instance
   * may keep the integrator and a workspace between calls. */
  nonsep_status (*integrate)(nonsep_instance* instance, const nonsep_integrator* integrator, double* q, double* p,
                             double* fsal_gradient, int* fsal_valid, size_t count, double dt, uint64_t steps,
                             uint64_t* grad_T_count, uint64_t* grad_V_count);
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
#define NONSEP_DEFINE_PLUGIN(table)                                                                   \
  NONSEP_PLUGIN_EXTERN_C __attribute__((visibility("default"))) const nonsep_plugin_api* const nonsep_plugin = \
      &(table)

#endif /* NONSEP_PLUGIN_ABI_H */
