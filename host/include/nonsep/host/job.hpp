#pragma once
// Job files: reading one, checking every part of it, and reporting all problems at once.
//
// The shape of a job file is documented key by key in docs/user-guide.md and docs/job-file.md, and formally in
// schemas/job.schema.json. Reading happens in three passes, each adding to one list of JobIssue:
//   1. parse_job_text  strict JSON: syntax (with line and column), duplicate keys, at most max_nesting_depth levels.
//   2. parse_job       structure and values that need no plugin: unknown keys, types, required keys, ranges,
//                      integrator options against nonsep::scheme_catalogue(), the time grid, initial states.
//                      The result, Job, is plain data: a std::variant of a single run and a study.
//   3. load_model      the plugin: it must load (/model/plugin), the parameters must match its metadata
//                      (/model/parameters/<name>), and the states must have the model's dimension (/initial/...).
// read_job is passes 1 and 2 on a file (at most max_job_file_bytes); load_job is all three, reporting the
// problems of every pass together. Every issue names a JSON Pointer (RFC 6901) into the job file, what was found
// there and what is allowed. The reader is split by the job file's sections, host/src/job/*.cpp.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "nonsep/core/analysis/indicator.hpp"
#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/host/json/issues.hpp"
#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/host/time_grid.hpp"

namespace nonsep::host {

namespace formula {
struct FormulaModel;  // nonsep/host/formula/formula_model.hpp
}

// Thrown by load_job with every issue of the file (never empty). what() is the full report, one issue a line.
class InvalidJob : public std::runtime_error {
 public:
  InvalidJob(const std::filesystem::path& job_file, std::vector<JobIssue> issues);
  const std::vector<JobIssue>& issues() const { return issues_; }

 private:
  std::vector<JobIssue> issues_;
};

// The initial states, state-major as in nonsep::PhaseSpaceBatch: component i of state b at b*dimension + i.
// `shape` says how the job wrote them: "single" (one object), "list" (an array of objects) or "grid".
// /initial/energy and /initial/solve_for (a grid only): every state of the grid is put on the energy shell H = energy
// by solving for one momentum component (energy_shell.cpp). "p1" takes the root p1 >= 0 nearest to 0, "-p1" the
// root p1 <= 0; the grid's value of that component is ignored. States for which H already exceeds `energy` at
// p_i = 0 (or that have no root within |p_i| <= 2^40) are left out of the run; `left_out` counts them.
struct EnergyShell {
  double energy = 0.0;
  std::size_t component = 0;  // i of p_i
  bool negative = false;      // "-p<i>": the root p_i <= 0
  std::string solve_for;      // as written
  std::size_t left_out = 0;
};

struct InitialStates {
  std::string shape;
  std::size_t dimension = 0;
  std::size_t count = 0;
  std::vector<double> q, p;
  std::optional<EnergyShell> shell;  // set by the reader; the states are solved when the model is loaded
  // A sweep (Job::sweep), set by load_model: state b belongs to parameter set parameter_set[b] (non-decreasing:
  // the job's states once per set, set after set); empty without a sweep.
  std::vector<std::size_t> parameter_set;
};

// A parameter of /model/parameters given as several values (a sweep): an array of values, {"values": [...]} or
// {"from": a, "to": b, "count": n}. The run takes every parameter set of the product of the swept parameters (in
// the order of their names, the last one varying fastest) with every initial state: one trajectory per pair, set
// after set.
struct SweptParameter {
  std::string name;
  std::vector<nlohmann::json> values;
  // JSON Pointer of values[i]: `values_path` + "/" + i for a list; empty for a range (the parameter's own path).
  std::string values_path;
};

// A convergence study (/study): the job's model and initial state are run to /time/t_end by each integrator at
// each of its step counts, and the errors at t_end are compared (study/convergence_study.hpp). Step counts are per
// integrator: the study's list (/study/steps, or /study/dt turned into counts as TimeGrid does) unless the integrator
// gives its own.
struct StudyIntegrator {
  std::string label;    // /study/integrators/<i>/label, default "<scheme> <order>" ("triplet 4/3"; "basic")
  IntegratorSpec spec;  // as /integrator of a single run, sharing /hamiltonian
  std::vector<std::uint64_t> steps;  // distinct, in increasing order; dt = t_end / steps
  std::string steps_from;            // where the counts came from: "study.steps", "study.dt", "integrator.steps", ...
};
struct Study {
  HamiltonianForm form = HamiltonianForm::TTV;  // /hamiltonian, shared by every integrator
  double t_end = 0.0;                           // /time/t_end
  std::vector<StudyIntegrator> integrators;
  // /study/reference: the exact state at t_end, for the phase-space error; empty when not given.
  std::vector<double> reference_q, reference_p;
  // /study/reference_run (instead of /study/reference): run first, with its one step count; its end state is the
  // reference.
  std::optional<StudyIntegrator> reference_run;
  // /study/repeats: each run is repeated this many times for its wall time (work_precision.csv: the median).
  int repeats = 1;
};

// /analysis/poincare: the crossings of every trajectory with the hyperplane normal . (q, p) = offset of phase space
// (poincare.csv; observers/poincare_section.hpp).
enum class CrossingDirection { up, down, both };  // "+": s = normal . (q, p) - offset goes from < 0 to >= 0
struct PoincareSection {
  std::vector<double> normal;  // 2n numbers, n for q then n for p ("component": "q1" is the unit vector of q1)
  double offset = 0.0;         // /analysis/poincare/value (or offset)
  CrossingDirection direction = CrossingDirection::up;
  std::optional<std::uint64_t> max_crossings;  // a trajectory stops ("completed", with a message) after this many
};

// /analysis/lyapunov: Benettin's finite-time Lyapunov exponents through the tangent map of the run's integrator.
struct LyapunovAnalysis {
  std::size_t vectors = 1;              // k: the k largest exponents
  std::uint64_t renormalize_every = 1;  // steps between re-orthonormalisations
  std::uint64_t every = 0;              // lyapunov.csv every this many steps; 0: no time series
};

// Samples of one signal a trajectory keeps in memory before they are written to its indicator's sample file
// (observers/sampled_indicator.hpp; 16 kB).
inline constexpr std::size_t samples_in_memory = 1024;

// Per-trajectory analysis of a single run (/analysis).
struct Analysis {
  std::optional<PoincareSection> poincare;   // /analysis/poincare
  std::optional<LyapunovAnalysis> lyapunov;  // /analysis/lyapunov
  // The indicators asked for (/analysis/frequencies, /lyapunov, /megno, /sali, /gali, /fli, /ofli), in the order of
  // their columns (host/src/job/indicators.cpp: the one list): those that follow tangent vectors and those that need
  // samples of the state (nonsep::needs_samples).
  IndicatorList indicators;
  // The ones that follow tangent vectors, in order.
  IndicatorList tangent_indicators() const { return select(false); }
  // The ones that need samples of the state, in order.
  IndicatorList sampled_indicators() const { return select(true); }
  // Tangent vectors per trajectory the run must follow, shared by every indicator: the most any of them needs; 0
  // for none.
  std::size_t tangent_vectors() const {
    std::size_t k = 0;
    for (const auto& indicator : indicators) k = std::max(k, indicator->needs().tangent_vectors);
    return k;
  }
  // The job file's key of the first indicator that follows tangent vectors, for messages ("" for none).
  std::string tangent_key() const {
    const IndicatorList tangent = tangent_indicators();
    return tangent.empty() ? "" : "/analysis/" + tangent.front()->name();
  }
  // /analysis/closest_return_after: from this time on, the smallest Euclidean phase-space distance
  // |(q, p) - (q0, p0)| to the trajectory's initial state is tracked at every step (summary: closest_return).
  std::optional<double> closest_return_after;
  // /analysis/max_relative_energy_error: a trajectory whose |H - H0| / |H0| exceeds it where H is evaluated retires
  // as "inaccurate"; absent: no bound.
  std::optional<double> max_relative_energy_error;
  // /analysis/error_estimate: a second run with half the step estimates every trajectory's global error
  // (observers/error_estimate.hpp).
  bool error_estimate = false;

 private:
  IndicatorList select(bool sampled) const {
    IndicatorList chosen;
    for (const auto& indicator : indicators)
      if (needs_samples(*indicator) == sampled) chosen.push_back(indicator);
    return chosen;
  }
};

// When a run saves checkpoint.json (host/include/nonsep/host/checkpoint/checkpoint_file.hpp) so that `nonsep run
// --resume` can continue it: after every `every_steps` steps and/or once `every_seconds` of wall time have passed since
// the last one (0 turns either off), and always when the run is interrupted.
struct CheckpointPolicy {
  std::uint64_t every_steps = 0;
  double every_seconds = 60.0;
};

// /output/format: where the samples and the tables go. csv: trajectory.csv (streamed) and the CSV tables; hdf5:
// results.h5 (observers/hdf5_sample_writer.hpp, output/hdf5_*.hpp) instead of trajectory.csv, with the CSV tables
// (kept as well) copied into it at the end. A study refuses hdf5 (it writes convergence.csv only).
enum class OutputFormat { csv, hdf5 };

// /integrator {"scheme": "auto", "tolerance": e, "measure": "phase" | "energy"}: the scheme and step are chosen by
// pilot runs before the run (study/scheme_choice.hpp), which then replaces SingleRun::integrator and divides its
// time grid.
struct AutoScheme {
  enum class Measure { phase, energy };
  double tolerance = 1e-6;
  Measure measure = Measure::phase;
};
inline constexpr double auto_tolerance_min = 1e-14, auto_tolerance_max = 0.1;

// A single run (a job without /study): one integrator over one time grid for every initial state.
struct SingleRun {
  // /hamiltonian and /integrator, defaults filled in from the catalogue; with "auto", the chosen one once
  // choose_scheme has run (until then the first candidate).
  IntegratorSpec integrator;
  std::optional<AutoScheme> auto_scheme;  // /integrator/scheme "auto"
  TimeGrid time;
  std::uint64_t every = 1;                  // /output/every; 0: no trajectory file
  std::uint64_t energy_every = 0;           // /output/energy_every; 0: H only at samples, start and end
  OutputFormat format = OutputFormat::csv;  // /output/format
  Analysis analysis;                        // /analysis
  CheckpointPolicy checkpoint;              // /checkpoint
};

struct Job {
  std::filesystem::path file;       // the job file as given
  std::filesystem::path directory;  // its folder: relative paths in the job resolve against it
  std::string plugin;               // /model/plugin: a name or a path
  // /model/formula (instead of /model/plugin): load_model compiles it (or finds it in the cache) and sets `plugin`
  // to the plugin's path and `formula_cache_key` to its cache entry (formula/plugin_cache.hpp).
  std::shared_ptr<const formula::FormulaModel> formula;
  std::string formula_cache_key;
  nlohmann::json parameters = nlohmann::json::object();  // /model/parameters with a single value (not swept)
  std::vector<SweptParameter> sweep;  // /model/parameters with several values, by name (as the document orders them)
  InitialStates initial;              // a study has exactly one state
  std::filesystem::path output_directory;  // /output/directory resolved against `directory`
  // What the job does: a single run, or a convergence study (/study, which has no /integrator, /analysis or
  // /checkpoint and a /time of its own).
  std::variant<SingleRun, Study> plan;

  bool is_study() const { return std::holds_alternative<Study>(plan); }
  // The parameter sets of the sweep (1 without one), and set s: `parameters` with the swept values of set s.
  std::size_t parameter_sets() const;
  nlohmann::json parameter_set(std::size_t s) const;
  // The plan as the kind the caller has checked it is (std::bad_variant_access otherwise: a programming error).
  const SingleRun& run() const { return std::get<SingleRun>(plan); }
  const Study& study() const { return std::get<Study>(plan); }
};

// Largest accepted number of initial states and of steps; larger values are reported as out of range.
inline constexpr std::size_t max_initial_states = 1'000'000;
// Largest accepted number of initial values, states times dimension (2^24: 128 MiB for q and as much for p; a
// million states of dimension 16 fit), so that a grid written in a few lines cannot ask for more memory and time
// than a machine has.
inline constexpr std::size_t max_initial_values = 16'777'216;
// H is evaluated from one n x n Hessian per state (nonsep::EnergyEvaluator, a block's states a few at a time) for a
// plugin without Hessian-vector products or its own energy_TTV/energy_VVT: such a model whose single Hessian would
// take more than this many numbers (1 GiB) is refused before the run (dimension at most 11585).
inline constexpr std::size_t max_hessian_values = std::size_t{1} << 27;
// Largest job file read (64 MiB); a longer file, or a device that never ends such as /dev/zero, is an issue at "".
inline constexpr std::size_t max_job_file_bytes = std::size_t{64} << 20;

// Pass 1: parse_job_text (nonsep/host/json/strict_json.hpp, included by those who call it).

// Pass 2. Reads `document` into a Job, adding an issue for everything wrong. `job_file` locates relative paths
// and names the default output folder. The returned Job is meaningful only if no issue was added.
Job parse_job(const nlohmann::json& document, const std::filesystem::path& job_file, std::vector<JobIssue>& issues);

// Pass 3 (parameters). Checks `given` (the job's /model/parameters, an object) against a plugin's declared
// parameters: known names, then the one rule of nonsep::sdk::check_parameter_value that the SDK and the plugin
// loader apply too (nonsep/sdk/parameters.hpp: an integer is an integral number, 2.0 included, of magnitude at
// most 2^53; a number is finite; bounds are inclusive).
void check_model_parameters(const nlohmann::json& given, const std::vector<PluginParameter>& declared,
                            std::vector<JobIssue>& issues);

// Pass 3 (sweep). Checks every value of job.sweep as check_model_parameters checks a single value; an issue names
// the value and where it is (/model/parameters/<name>/<i>, or the range's /model/parameters/<name>).
void check_swept_parameters(const Job& job, const std::vector<PluginParameter>& declared,
                            std::vector<JobIssue>& issues);

// Pass 3 (dimension). Checks the initial states against the model's dimension; the issue says that components count
// from 0 (q0 .. q<n-1>) and, for a formula model (`formula`), that its dimension is the largest index its formulas
// use plus one, so that q1 and q2 written for two coordinates read as the three they are.
void check_dimension(const InitialStates& initial, std::size_t model_dimension, std::vector<JobIssue>& issues,
                     bool formula = false);

// A job ready to run: the checked job, its plugin and a model instance created with the job's parameters (those of
// the first parameter set of a sweep).
struct LoadedJob {
  Job job;
  Plugin plugin;
  PluginModel model;
};

// The solved Hamiltonian as summary.json's "hamiltonian" names it: "TTV" or "VVT" (the form of a product-form
// model), or "general" for a model given by H(q, p) itself.
inline std::string hamiltonian_name(const Plugin& plugin, HamiltonianForm form) {
  return plugin.general_hamiltonian() ? "general" : form == HamiltonianForm::TTV ? "TTV" : "VVT";
}

// Puts the `q`, `p` (states of dimension n, state-major) on `shell` with `model`'s H of the form `form`, keeping in
// place the states that reach it; returns how many were left out.
std::size_t solve_on_energy_shell(const PluginModel& model, HamiltonianForm form, const EnergyShell& shell,
                                  std::size_t n, std::vector<double>& q, std::vector<double>& p);

// The run's trajectories (pass 3, sweep.cpp): loaded.job.initial becomes the job's states once per parameter set
// (Job::parameter_sets; InitialStates::parameter_set says whose), each set's states put on the energy shell (when
// /initial/energy is given; EnergyShell::left_out is then the total over the sets) with an instance of the set's
// own parameters; for every sweep, of one value too. Every set passes the checks of for_each_parameter_set
// (job/sections.hpp): a set the plugin refuses (/model/parameters) or whose model's dimension differs from set 0's
// (the swept key) is refused. Other issues: too many trajectories (/model/parameters), a plugin without Hessians or
// a shell no state of any set reaches (/initial/energy).
void make_trajectories(LoadedJob& loaded, std::vector<JobIssue>& issues);

// Checks the plugin's grad T and grad V against finite differences of its value_T and value_V at up to 16 of the
// job's initial states (evenly spread), on an instance of its own (of the state's parameter set in a sweep), when the
// plugin has values and a dimension of at most 512. The first disagreement beyond 1e-4 relative to max(1, |finite
// difference|) is an issue at /model/plugin naming the function, the state and both numbers, and `nonsep inspect PLUGIN
// --check`. States where the plugin fails or a number is not finite are left to the run.
void check_gradients_at_initial_states(const LoadedJob& loaded, std::vector<JobIssue>& issues);

// What a single run keeps in memory, estimated before anything runs (load_model: `nonsep validate` and `nonsep run`)
// from the job alone, for the `trajectories` one process steps (all of them, or its share under mpirun) of
// dimension n with k tangent vectors, 8 bytes a number:
//   /initial              the job's states (every process holds all of them), and per trajectory stepped the
//                         driver's state, its copy at each chunk's start and the final state recorded: 4 x 2n
//   <the tangent key>     the k vectors and their copy at each chunk's start, and SALI/GALI's factor: 2 x (2nk + k^2)
//   /analysis/error_estimate  the half-step states at every comparison step, (2n + 2) each, and that run's states
//   /analysis/poincare, /analysis/closest_return_after  one more state per trajectory each
//   /output/every         one sample of every trajectory waiting: trajectory.csv's rows as text (about 25 bytes a
//                         number), or results.h5's rows and their chunk buffer: 2 x (2n + 1)
//   /checkpoint           checkpoint.json's states, tangent vectors and Lyapunov sums as numbers, as JSON values
//                         and as text, checkpoint_bytes_per_number a number (written every minute by default, and on
//                         SIGINT)
// Each part names the job file's key that asks for it; the total is a floor (buffers of a few MB, the plugin's
// own memory and the scheme's private state are left out).
struct MemoryEstimate {
  struct Part {
    std::string key;   // the job file's key that asks for it ("/initial", "/analysis/lyapunov", ...)
    std::string what;  // "the tangent vectors (32 per trajectory)"
    double bytes = 0.0;
  };
  std::vector<Part> parts;  // largest first
  double total() const;
};
// Bytes per number of checkpoint.json while it is written: the saved copy (8), a JSON document of strings
// (format_number's shortest text, as nlohmann::json values: about 100), its text for the checksum and its text
// (about 20 each); measured about 145 a number more for paper2d's tangent vectors (docs/user-guide.md, Memory).
inline constexpr double checkpoint_bytes_per_number = 160.0;
// `trajectories` of the job stepped by this process (its share under mpirun), the job's states all held.
MemoryEstimate estimate_run_memory(const LoadedJob& loaded, std::size_t trajectories);
// The bytes this process can still take, with where the figure comes from: the least of /proc/meminfo's
// MemAvailable, a cgroup's memory.max less memory.current, and RLIMIT_AS (ulimit -v) less the address space in use;
// sysconf's free pages when /proc/meminfo cannot be read. Nothing when none can be known.
struct AvailableMemory {
  double bytes = 0.0;
  std::string source;  // "MemAvailable in /proc/meminfo", "RLIMIT_AS (ulimit -v) less the address space in use", ...
};
std::optional<AvailableMemory> available_memory();
// An issue at the key of the largest part when estimate_run_memory's total exceeds available_memory(), naming
// both figures and the largest parts; nothing otherwise (or when the available memory cannot be known).
std::optional<JobIssue> memory_issue(const LoadedJob& loaded, std::size_t trajectories);

// Passes 1 and 2 on the file at `job_file`. Nothing when the file cannot be read (missing, a directory, larger than
// max_job_file_bytes: an issue at "") or is not strict JSON; otherwise the Job, meaningful only if no issue was added.
std::optional<Job> read_job(const std::filesystem::path& job_file, std::vector<JobIssue>& issues);

// Pass 3 on a job read by read_job, whether or not it had issues (so that all are reported at once): loads
// job.plugin, checks the parameters, creates the model and checks the states' dimension. Nothing when the job
// names no plugin (/model/plugin was missing or invalid) or this pass added an issue. A single run must fit the
// available memory (memory_issue) with its trajectories shared by `processes` (mpirun's ranks).
std::optional<LoadedJob> load_model(Job job, std::vector<JobIssue>& issues, std::size_t processes = 1);

// What pass 3 checks of a formula job (job.formula) without compiling it, for `nonsep validate` and before the
// compile: the parameters and swept values against the formula's, the states' dimension, and for a model given by
// H(q, p) the schemes that apply to it (Chin's need the product form). Issues added; nothing else.
void check_formula_job(const Job& job, std::vector<JobIssue>& issues);

// All three passes on the file at `job_file`. Throws InvalidJob listing every issue (an unreadable file is an
// issue at path ""). Exceptions other than InvalidJob mean a bug or an exhausted machine.
LoadedJob load_job(const std::filesystem::path& job_file, std::size_t processes = 1);

}  // namespace nonsep::host
