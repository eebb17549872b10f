#pragma once
// Internal to the job reader (host/src/job/): one reader per section of a job file, each in its own file, called by
// parse_job (parse_job.cpp) in the order of the key-by-key table of docs/user-guide.md. Each takes the document as its
// key table read it (a KeyReader: the document's keys known, required ones present, scalars of their type) or the
// section's value, and a Checker, returns what it read, and adds one issue per problem; what it returns is
// meaningful only if it added none.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "job_keys.hpp"
#include "key_reader.hpp"
#include "nonsep/core/runtime/scheme_catalogue.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/json/checker.hpp"
#include "nonsep/host/json/parameter_check.hpp"

namespace nonsep::host::job_reader {

// /model (model.cpp): sets job.plugin, job.parameters and job.sweep.
void read_model(Checker& check, const KeyReader& document, Job& job);
// The declared parameter `name` (model.cpp), or nothing and an issue at `path` naming the plugin's parameters.
const PluginParameter* find_parameter(Checker& check, const std::vector<PluginParameter>& declared,
                                      const std::string& name, const std::string& path);
// /model/parameters/<name> given as an array, {"values": [...]} or {"from", "to", "count"} (sweep.cpp): a swept
// parameter, or nothing and an issue.
std::optional<SweptParameter> read_swept_parameter(Checker& check, const std::string& name, const json& value,
                                                   const std::string& path);
// The trajectories of a run, the job's states times its parameter sets, within max_initial_states and
// max_initial_values (sweep.cpp); an issue at /model/parameters otherwise.
void check_sweep_size(Checker& check, const Job& job);

// /hamiltonian and /integrator (integrator.cpp).
HamiltonianForm read_hamiltonian(const KeyReader& document);
// /integrator of a run; with "scheme": "auto", also its tolerance and measure into `auto_scheme`.
IntegratorSpec read_integrator(Checker& check, const KeyReader& document, HamiltonianForm form,
                               std::optional<AutoScheme>& auto_scheme);
// One integrator object at `path` (a run's /integrator, an entry of /study/integrators, /study/reference_run) read
// by its table: "scheme", that scheme's options from the catalogue and `extra`'s keys (which the caller reads through
// keys()); `what` is the message for a value that is not an object.
class IntegratorReader {
 public:
  IntegratorReader(Checker& check, const json& integrator, const std::string& path, HamiltonianForm form,
                   const KeyTable* extra, const std::string& what);
  IntegratorReader(const IntegratorReader&) = delete;  // its KeyReader refers to its table
  IntegratorReader& operator=(const IntegratorReader&) = delete;
  const IntegratorSpec& spec() const { return spec_; }
  // Whether the object names a scheme of the catalogue (else spec() is no scheme's, and an issue says so).
  bool scheme_known() const { return scheme_ != nullptr; }
  const KeyReader& keys() const { return keys_; }

 private:
  const Scheme* scheme_;
  KeyTable table_;
  KeyReader keys_;
  IntegratorSpec spec_;
};

// /time (time.cpp): a run's {"dt", "t_end" or "steps"}, a study's {"t_end"}.
TimeGrid read_time(Checker& check, const KeyReader& document);
TimeGrid read_study_time(Checker& check, const KeyReader& document);
// The step count from t_end and dt (TimeGrid's steps_to_reach) within max_steps, or an issue at `path` that shows
// `found` and the count it would need (or that t_end / dt overflows). t_end / dt must be positive.
std::optional<std::uint64_t> step_count(Checker& check, double t_end, double dt, const std::string& path,
                                        const std::string& found);

// One axis of a grid (initial.cpp): a number, {"from", "to", "count"} or {"values": [...]}; nothing and an issue
// when invalid.
std::optional<std::vector<double>> read_axis(Checker& check, const json& value, const std::string& path);
// Value k of the range {"from", "to", "count"} (a grid's axis, a swept parameter): `from` for k = 0 (and for a count
// of 1) and `to` for k = count - 1, exactly; between them the double nearest to from + (to - from) k / (count - 1)
// computed exactly from the shortest decimals of from and to (0 to 0.3 in 16 values: 0.06 at k = 3, as written;
// ends whose decimals lie more than 20 digits apart, such as 1e-30 and 1e10, in double arithmetic). Never outside
// [from, to], never infinite.
double range_value(double from, double to, std::size_t count, std::size_t k);
// /initial (initial.cpp). read_state appends one state {"q", "p"} at `path` to `states` when it is valid;
// `first_path` names the state whose dimension the others must have.
InitialStates read_initial(Checker& check, const KeyReader& document, const std::filesystem::path& directory);
// A CSV file of initial states (/initial/file) is read a row at a time within these bounds, checked as it is read
// (a file without line ends is refused after at most this many cells of its first line): at most 2^21 columns
// (states of dimension 2^20; larger ones as .npy) and 32 bytes per cell (a float64 needs at most 24).
inline constexpr std::size_t max_initial_csv_columns = std::size_t{1} << 21;
inline constexpr std::size_t max_initial_csv_cell_bytes = 32;
// /initial/file (initial_file.cpp): the states of a .npy or .csv file, relative to `directory` (the job's folder).
void read_initial_file(Checker& check, const json& initial, const std::filesystem::path& directory,
                       InitialStates& states);
// /initial/energy and /initial/solve_for of a grid (energy_shell.cpp), into states.shell.
void read_energy_shell(Checker& check, const KeyReader& initial, InitialStates& states);
void read_state(Checker& check, const json& value, const std::string& path, InitialStates& states,
                const std::string& first_path, const std::string& what = "a state {\"q\": [...], \"p\": [...]}");

// /study (study/convergence_study.cpp), with the study's end time (0 when /time/t_end is invalid: the step sizes are
// then only checked, not turned into counts).
Study read_study(Checker& check, const json& study, HamiltonianForm form, double t_end);

// /output, /analysis and /checkpoint (outputs.cpp). read_output sets job.output_directory and, in a single run,
// its every and energy_every (job.plan must already say which kind of job it is).
void read_output(Checker& check, const KeyReader& document, Job& job);
// read_analysis needs the dimension of the initial states (0 when unknown) for /analysis/poincare and /lyapunov.
Analysis read_analysis(Checker& check, const json& value, std::size_t dimension);
// /analysis/poincare and the indicators (/analysis/frequencies and the chaos indicators: dynamics.cpp, indicators.hpp)
// of /analysis as its KeyReader checked it, into `analysis`.
void read_dynamics(Checker& check, const KeyReader& analysis_keys, std::size_t dimension, Analysis& analysis);
CheckpointPolicy read_checkpoint(Checker& check, const json& value);

}  // namespace nonsep::host::job_reader

namespace nonsep::host {

// Every parameter set s of the job, in order, with an instance of its parameters (set 0: loaded.model) (sweep.cpp):
// the one place where what a run needs of every set is checked (make_trajectories runs it for every sweep). A set the
// plugin refuses (an issue at /model/parameters), or whose model's dimension differs from set 0's (an issue at the
// swept parameter, naming both sets: a sweep cannot change the dimension), is reported and ends the loop: false
// then. Otherwise calls visit(s, model) for each set and returns true.
bool for_each_parameter_set(const LoadedJob& loaded, std::vector<JobIssue>& issues,
                            const std::function<void(std::size_t, const PluginModel&)>& visit);

}  // namespace nonsep::host
