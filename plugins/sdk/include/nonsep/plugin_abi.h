/* nonsep plugin ABI, version 6. The boundary evaluates: the host owns every scheme and crosses the boundary once
 * per batch of states for a gradient (or a Hessian, a value, a third derivative, a Hessian-vector product).
 * One number says everything a plugin offers: abi_version fixes the table's size (one struct size per version) and
 * the arguments of the stepping kernel. Each version appends optional entries to the previous one's table, so an
 * older table is a prefix of this one and still loads, without the entries it lacks:
 *   3  the required entries, values, Hessians, directional third derivatives     NONSEP_PLUGIN_V3_STRUCT_SIZE
 *   4  + the separable part K(p) + U(q), Hessian-vector products, the stepping kernel chin_steps (its argument
 *        layout then given by "kernels": {"version": K} in the metadata; the host steps these plugins through
 *        their gradients, since version 5's kernels also evaluate the gradient their steps start from), the product
 *        term of H in one pass (energy_TTV, energy_VVT)                           NONSEP_PLUGIN_V4_STRUCT_SIZE
 *        (a version-4 table as first published ends before energy_TTV: NONSEP_PLUGIN_V4_KERNEL_STRUCT_SIZE)
 *   5  + the directional derivative of grad H, hvp_H (the tangent maps of the comparators), the tangent kernel
 *        chin_tangent_steps; chin_steps takes the arguments below and the metadata's "kernels" has no "version"
 *                                                                                  NONSEP_PLUGIN_V5_STRUCT_SIZE
 *   6  + models given by H(q, p) itself: value_H, grad_H, and hvp_H with the form NONSEP_FORM_GENERAL; the metadata's
 *        "hamiltonian_form" says which kind a plugin is; the Gauss-Legendre stepping kernel gauss_steps, of either
 *        kind                                                                      NONSEP_PLUGIN_V6_STRUCT_SIZE
 *        (a version-6 table without gauss_steps ends before it: NONSEP_PLUGIN_V6_EVALUATION_STRUCT_SIZE)
 * docs/plugin-abi.md lists the versions and their entries. Version 2 had a fused stepping function integrate() with
 * a stepper of its own; version 1 exported a function, nonsep_plugin_entry, returning the table instead of the
 * pointer below. Plugins of either are refused: rebuild them against the installed SDK.
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
 *   1. abi_version is 6 (NONSEP_PLUGIN_ABI_VERSION), 5, 4 or 3   (refused with "expected 6, 5, 4 or 3, found N")
 *   2. struct_size is the size of that version's table (the list above; refused with expected and found sizes);
 *      the entries an older table lacks are absent
 *   3. the required functions are non-null        (metadata_json, create, destroy, dimension, last_error; and
 *                                                   grad_T, grad_V for the product form, value_H, grad_H for a
 *                                                   general H)
 *   4. metadata_json() returns valid JSON of the shape below, whose capabilities match the table.
 *
 * Batch layout (same as nonsep/core/base/model.hpp): `count` states of dimension n, state-major and contiguous.
 * Component i of state b is at x[b*n + i]; gradient outputs have the same layout; Hessian outputs hold count
 * row-major n x n matrices, entry (i, j) of state b at out[b*n*n + i*n + j]. Value outputs hold one double
 * per state. Directions (u of the third derivatives, v of the Hessian-vector products; one per state) and their
 * outputs have the gradient layout.
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
 *     "hamiltonian_form": "product" | "general",   (version 6; absent: "product")
 *     "dimension": { "fixed": 1 }                  or  { "parameter": "dimension" },
 *     "parameters": [ { "name": "dimension", "type": "integer" | "number" | "boolean",
 *                       "default": 2, "minimum": 1, "maximum": 64, "unit": "", "description": "..." } ],
 *     "thread_safe": true,
 *     "capabilities": { "value_T": true, "value_V": true, "hessian_T": true, "hessian_V": true,
 *                       "d3T": true, "d3V": true, "grad_K": false, "grad_U": true, "value_U": true, ...,
 *                       "hvp_T": true, "hvp_V": true, "chin_steps": true,
 *                       "energy_TTV": false, "energy_VVT": false, "hvp_H": true, "chin_tangent_steps": true,
 *                       "gauss_steps": true },
 *     "kernels": { "instruction_sets": ["x86-64", ...] }          exactly when chin_steps is non-null
 *                                                                  (chin_tangent_steps only with chin_steps)
 *   }
 * "minimum", "maximum" and "unit" may be absent; "thread_safe" is required. Each capability is true exactly
 * when the table's pointer of that name is non-null (an absent capability counts as false).
 *
 * Two kinds of model (version 6). "product": H = T_i V_ij T_j (+ K + U) or its VVT form, given by T and V and
 * their derivatives (every entry up to version 5; grad_T and grad_V required, value_H and grad_H null); Chin's
 * schemes split it, and the schemes that integrate H itself take it too. "general": H(q, p) of any shape, given by
 * value_H and grad_H (both required) and optionally hvp_H with the form NONSEP_FORM_GENERAL and gauss_steps; every
 * entry of T, V, K, U, Chin's kernels and energy_TTV/VVT is null. Only the schemes that integrate H itself
 * (Gauss-Legendre, implicit midpoint, Tao's extended phase space) take it; the host refuses Chin's schemes for it
 * before anything runs.
 */
#ifndef NONSEP_PLUGIN_ABI_H
#define NONSEP_PLUGIN_ABI_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define NONSEP_PLUGIN_ABI_VERSION 6u
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

/* The forms of the solved Hamiltonian (nonsep/core/schemes/integrator_description.hpp's HamiltonianForm). */
#define NONSEP_FORM_TTV 0u     /* H = T_i V_ij T_j (+ K + U) */
#define NONSEP_FORM_VVT 1u     /* H = V_i T_ij V_j (+ K + U) */
#define NONSEP_FORM_GENERAL 2u /* H(q, p) of a "general" plugin (hvp_H only) */

/* The arguments of chin_steps (below): `steps` times a schedule of `substeps` basic steps of eq. (expalg) of every
 * state, in place (a triplet composition's step is its schedule of 3^levels basic steps); or, with `terms` >= 2,
 * `steps` steps of the multi-product expansion of eqs. (mpe43, mpe63): term k = m..1 takes k basic steps of eps[k-1] =
 * cbrt(dt/k) from the step's start, the result is y_m + sum_{k<m} weights[k-1] (y_k - y_m), and the next step starts
 * from the outer gradient evaluated at that point (core chin_expansion_stages.hpp). With `steps` 0 the call only
 * evaluates outer_gradient at the point, q and p left as they are: the host asks the kernel for the gradient its steps
 * start from, so that every gradient the steps use comes from the kernel's own code. Version 4 with "kernels":
 * {"version": 3} took the same arguments without the call of no steps; the host steps such plugins through their
 * gradients. */
typedef struct nonsep_chin_steps_args {
  uint32_t form;             /* NONSEP_FORM_TTV or NONSEP_FORM_VVT */
  uint32_t instruction_set;  /* index into the metadata's "kernels": {"instruction_sets": [...]} */
  double t1, t2, v0, v1, v2; /* the coefficients of eq. (expalg) */
  const double* eps;         /* cbrt(dt) of each sub-step, for every state; or, with one sub-step, one number for
                                every state or one per state */
  size_t eps_count;          /* substeps, or (substeps 1) 1 or count; with terms, terms */
  size_t substeps;           /* >= 1: basic steps per step, sub-step s with eps[s] */
  uint64_t steps;            /* >= 1; 0: only the outer gradient at the point (above) */
  size_t count;              /* states, in the batch layout */
  double* q;                 /* count*n, advanced in place */
  double* p;                 /* count*n, advanced in place */
  double* outer_gradient;    /* count*n: in, the outer flows' gradient at the current point (grad V(q) in
                                TTV, grad T(p) in VVT); out, the same at the final point */
  double* inner_gradient;    /* count*n, scratch */
  const double* weights;     /* terms numbers c_1..c_m of the expansion; NULL with terms 0 */
  size_t terms;              /* 0: basic steps; m >= 2: expansion steps (then substeps 1 and eps_count m), whose
                                outer_gradient out is not at the final point (the host evaluates it anew) */
} nonsep_chin_steps_args;

/* The arguments of chin_tangent_steps (below): the basic steps of `steps` (terms 0; with `steps.steps` 0 only the
 * outer gradient, as chin_steps), each flow followed by its linear map applied to `vectors` tangent vectors per state
 * (core chin_tangent_stages.hpp): a kick p <- p - c eps V'(q) maps dp <- dp - c eps V''(q) dq, a drift
 * q <- q + c eps T'(p) maps dq <- dq + c eps T''(p) dp, each at the point the flow started from. Vector j of state b
 * is at (b*vectors + j)*n of tangent_q (its dq) and tangent_p (its dp). */
typedef struct nonsep_chin_tangent_steps_args {
  nonsep_chin_steps_args steps; /* as for chin_steps, terms 0 */
  size_t vectors;               /* k, 1 <= k <= 2n */
  double* tangent_q;            /* count*k*n, mapped in place */
  double* tangent_p;            /* count*k*n, mapped in place */
} nonsep_chin_tangent_steps_args;

/* The arguments of gauss_steps (below): one step of Gauss-Legendre collocation of `count` states, each iterated to
 * convergence from its starting stages, in the arrangement, starting values, stopping rule and compensated sum of
 * the core's gauss_stages.hpp (whose GaussStepsCall this is). Each state's last step is a row of 1 + 4n + 2sn
 * numbers: dt (0: none), its end point q and p, the rounding errors of its compensated sum (q, p), and its stages' L
 * (q parts, then p parts; stage j, component k at j*n + k). A state starts from its row when the row's dt and end
 * point are this step's dt and its point, bit for bit, else from Z = 0 and no carried error. */
typedef struct nonsep_gauss_steps_args {
  uint32_t form;           /* NONSEP_FORM_TTV, NONSEP_FORM_VVT (product form) or NONSEP_FORM_GENERAL */
  uint32_t stages;         /* s, 1 to 8 */
  uint32_t max_iterations; /* >= 1 */
  double dt;               /* the step */
  const double* mu;        /* s*s, row-major: mu_ij = a_ij / b_j */
  const double* hb;        /* s: fl(dt b_i) */
  const double* nu;        /* s*s, row-major: the starting values' extrapolation; NULL: every step from Z = 0 */
  size_t count;            /* states, in the batch layout */
  double* q;               /* count*n: in, the states; out, the converged states advanced */
  double* p;               /* count*n, as q */
  const double* memory;    /* count rows (above): each state's last step */
  double* next_memory;     /* count rows out: this step, for the converged states */
  double* points_q;        /* s*count*n out (converged states): the stage points of the last evaluation, stage i,
                              component k of state b at i*count*n + b*n + k */
  double* points_p;        /* s*count*n out: the same, p */
  int32_t* iterations;     /* count out: the iterations each state took */
  uint8_t* outcome;        /* count out: 0 converged, 1 an iterate not finite, 2 no convergence in max_iterations */
} nonsep_gauss_steps_args;

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

  /* ---- Version 4. Every entry below is optional (NULL when absent). ---- */

  /* The separable part: the solved Hamiltonian is H = T_i V_ij T_j + K(p) + U(q) (VVT: V_i T_ij V_j + K + U).
   * grad_K or grad_U, or both, make a model's separable part (an absent one is zero); values and Hessians as for
   * T and V, each present only with its gradient, and the value required with it (the energy of H needs it). The
   * host's schemes compose the exact flows of K and U with the basic step (core separable_composition.hpp). */
  nonsep_status (*grad_K)(nonsep_instance* instance, const double* p, double* out, size_t count);
  nonsep_status (*grad_U)(nonsep_instance* instance, const double* q, double* out, size_t count);
  nonsep_status (*value_K)(nonsep_instance* instance, const double* p, double* out, size_t count);
  nonsep_status (*value_U)(nonsep_instance* instance, const double* q, double* out, size_t count);
  nonsep_status (*hessian_K)(nonsep_instance* instance, const double* p, double* out, size_t count);
  nonsep_status (*hessian_U)(nonsep_instance* instance, const double* q, double* out, size_t count);

  /* Hessian-vector products: out[b*n + i] = sum_j T_ij(p_b) v[b*n + j], and so for V (at q), K and U (the last
   * two only with their gradients). O(n) memory per state where the Hessians take n^2. */
  nonsep_status (*hvp_T)(nonsep_instance* instance, const double* p, const double* v, double* out, size_t count);
  nonsep_status (*hvp_V)(nonsep_instance* instance, const double* q, const double* v, double* out, size_t count);
  nonsep_status (*hvp_K)(nonsep_instance* instance, const double* p, const double* v, double* out, size_t count);
  nonsep_status (*hvp_U)(nonsep_instance* instance, const double* q, const double* v, double* out, size_t count);

  /* The stepping kernel: args->steps times args->substeps basic steps of eq. (expalg) of args->count states (a
   * triplet composition's steps whole, its sub-steps' eps in turn), the stages those of the
   * core's own template with this model's gradients inlined, so that with the baseline instruction set the
   * numbers are bit for bit those of the host stepping through grad_T and grad_V. Announced with the metadata
   * object "kernels": {"instruction_sets": [...]} (version 4: {"version": K, ...}, not used by this host). A failed
   * evaluation returns its status (message by last_error) with q, p and outer_gradient undefined: the host then redoes
   * the steps through grad_T and grad_V. */
  nonsep_status (*chin_steps)(nonsep_instance* instance, const nonsep_chin_steps_args* args);

  /* The product term of the solved H in one pass, for a model that writes it out (a sparse model: its H then
   * costs about a gradient, where a gradient and a Hessian-vector product cost two passes and a third to take
   * their dot product): out[b] = T'(p_b) . V''(q_b) T'(p_b) (energy_TTV), V'(q_b) . T''(p_b) V'(q_b) (energy_VVT),
   * one number per state; K + U not included (the host adds value_K and value_U). Without them the host evaluates
   * H through the Hessian-vector products or the Hessians. */
  nonsep_status (*energy_TTV)(nonsep_instance* instance, const double* q, const double* p, double* out, size_t count);
  nonsep_status (*energy_VVT)(nonsep_instance* instance, const double* q, const double* p, double* out, size_t count);

  /* ---- Version 5. Optional (NULL when absent). ---- */

  /* The directional derivative of grad H: the Hessian of the solved H (K + U included) times a tangent (dq, dp),
   * for `form` NONSEP_FORM_TTV or NONSEP_FORM_VVT: out_q = d(dH/dq), out_p = d(dH/dp), each count*n numbers in the
   * gradient layout, one tangent (dq, dp) per state. With g = T'(p), dg = T''(p) dp, w = V''(q) g (TTV):
   *   out_q_k = V''''_ijkl g_i g_j dq_l + 2 V'''_ijk g_i dg_j + U''_kl dq_l
   *   out_p_k = 2 T'''_kil dp_l w_i + 2 T''_ki (V'''_ijl g_j dq_l + V''_ij dg_j) + K''_kl dp_l
   * (fourth derivatives of V, third of T; sums over repeated indices); VVT the same with (T, p, K) and (V, q, U)
   * swapped: g = V'(q), dg = V''(q) dq, w = T''(p) g,
   *   out_p_k = T''''_ijkl g_i g_j dp_l + 2 T'''_ijk g_i dg_j + K''_kl dp_l
   *   out_q_k = 2 V'''_kil dq_l w_i + 2 V''_ki (T'''_ijl g_j dp_l + T''_ij dg_j) + U''_kl dq_l.
   * The tangent maps of the schemes that integrate H itself (Gauss-Legendre, Tao's extended phase space) need it;
   * the host refuses them a plugin without it. A "general" plugin (version 6) takes NONSEP_FORM_GENERAL: out_q and
   * out_p are then the Hessian of its H(q, p) times (dq, dp). Another form returns NONSEP_UNSUPPORTED. */
  nonsep_status (*hvp_H)(nonsep_instance* instance, uint32_t form, const double* q, const double* p, const double* dq,
                         const double* dp, double* out_q, double* out_p, size_t count);

  /* The tangent kernel: chin_steps' basic steps with the tangent maps of their flows (args above), for the Lyapunov
   * exponents, MEGNO, SALI and GALI; the instruction sets those of chin_steps (present only with it), the stages and
   * the Hessian-vector products those of the core's template with this model inlined, so that with the baseline
   * instruction set the numbers are bit for bit those of the host stepping through grad_T, grad_V, hvp_T and hvp_V.
   * A failed evaluation returns its status with the arrays undefined: the host then redoes the steps through the
   * evaluations. */
  nonsep_status (*chin_tangent_steps)(nonsep_instance* instance, const nonsep_chin_tangent_steps_args* args);

  /* ---- Version 6. Present exactly in a "general" plugin (metadata "hamiltonian_form": "general"). ---- */

  /* H(q, p) itself, one number per state (out[b] = H(q_b, p_b)). */
  nonsep_status (*value_H)(nonsep_instance* instance, const double* q, const double* p, double* out, size_t count);
  /* Its gradient: dH_dq[b*n + i] = dH/dq_i, dH_dp[b*n + i] = dH/dp_i at (q_b, p_b), the gradient layout. */
  nonsep_status (*grad_H)(nonsep_instance* instance, const double* q, const double* p, double* dH_dq, double* dH_dp,
                          size_t count);

  /* ---- Version 6, optional, of either kind of model. ---- */

  /* The Gauss-Legendre stepping kernel: one step of args->count states (args above), grad H evaluated inside the
   * plugin with the model inlined, the same operations in the same order as the host's evaluation path, so that a
   * plugin compiled with the host's flags gives its numbers bit for bit. The host takes a step through it when every
   * state converged, and otherwise (or on a status other than NONSEP_OK) takes the step again through grad_T,
   * grad_V and the Hessian-vector products (or grad_H), which say what failed. */
  nonsep_status (*gauss_steps)(nonsep_instance* instance, const nonsep_gauss_steps_args* args);
} nonsep_plugin_api;

/* The size of a version-3 table: the entries before grad_K. */
#define NONSEP_PLUGIN_V3_STRUCT_SIZE offsetof(nonsep_plugin_api, grad_K)
/* The size of a version-4 table: the entries before hvp_H. */
#define NONSEP_PLUGIN_V4_STRUCT_SIZE offsetof(nonsep_plugin_api, hvp_H)
/* The size of a version-4 table as first published, ending with chin_steps: also loaded as version 4. */
#define NONSEP_PLUGIN_V4_KERNEL_STRUCT_SIZE offsetof(nonsep_plugin_api, energy_TTV)
/* The size of a version-5 table: the entries before value_H. */
#define NONSEP_PLUGIN_V5_STRUCT_SIZE offsetof(nonsep_plugin_api, value_H)
/* The size of a version-6 table. */
#define NONSEP_PLUGIN_V6_STRUCT_SIZE sizeof(nonsep_plugin_api)
/* The size of a version-6 table that ends before gauss_steps: also loaded as version 6, without the kernel. */
#define NONSEP_PLUGIN_V6_EVALUATION_STRUCT_SIZE offsetof(nonsep_plugin_api, gauss_steps)

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
