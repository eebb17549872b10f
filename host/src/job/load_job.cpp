// Reading a job file (at most max_job_file_bytes, never a directory), pass 3 (the plugin: load_model), and
// load_job, which runs all passes and throws InvalidJob with the issues of every pass together.
#include <cstdio>
#include <fstream>
#include <iostream>

#include "nonsep/core/runtime/integrator.hpp"
#include "nonsep/core/runtime/tangent_integrator.hpp"
#include "nonsep/host/formula/plugin_cache.hpp"
#include "nonsep/host/job.hpp"
#include "nonsep/host/json/checker.hpp"
#include "nonsep/host/json/strict_json.hpp"

namespace nonsep::host {

namespace {

// The schemes that integrate H itself (the catalogue's comparators), which a model given by H takes.
std::string schemes_integrating_h() {
  std::string names;
  for (const auto& scheme : Integrator::catalogue())
    if (scheme.family == "comparator") names += (names.empty() ? "" : ", ") + scheme.name;
  return names;
}

// The refusal of a Chin scheme for a model given by H, and what applies instead.
std::string chin_scheme_with_general_hamiltonian(const std::string& scheme, const std::string& plugin) {
  return "\"" + scheme + "\" with the plugin '" + plugin +
         "', a model given by H(q, p) itself: Chin's schemes (basic, triplet, mpe) split H into T(p) and V(q) and "
         "need H in product form, T_i V_ij T_j (+ K + U)";
}
std::string schemes_for_general_hamiltonian() {
  return "a scheme that integrates H itself: " + schemes_integrating_h() + ", or \"auto\"";
}

// The schemes (and the form) of `job` against a model given by H(q, p) itself, named `model`: Chin's schemes and the
// form VVT need the product form. Each refusal is an issue at the scheme's (or /hamiltonian's) key.
void check_schemes_for_general_hamiltonian(const Job& job, const std::string& model, std::vector<JobIssue>& issues) {
  if ((job.is_study() ? job.study().form : job.run().integrator.form) == HamiltonianForm::VVT)
    issues.push_back(
        {"/hamiltonian",
         "\"VVT\" with the plugin '" + model + "', a model given by H(q, p) itself, which has no T and V to exchange",
         "no form (TTV, the default): the forms choose between the product-form Hamiltonians "
         "T_i V_ij T_j and V_i T_ij V_j"});
  const auto check = [&](const IntegratorSpec& spec, const std::string& path) {
    if (!is_comparator(spec.scheme))
      issues.push_back(
          {path, chin_scheme_with_general_hamiltonian(spec.scheme, model), schemes_for_general_hamiltonian()});
  };
  if (job.is_study()) {
    const auto& integrators = job.study().integrators;
    for (std::size_t i = 0; i < integrators.size(); ++i)
      check(integrators[i].spec, "/study/integrators/" + std::to_string(i) + "/scheme");
    if (const auto& reference = job.study().reference_run) check(reference->spec, "/study/reference_run/scheme");
  } else if (!job.run().auto_scheme) {
    check(job.run().integrator, "/integrator/scheme");
  }
}

// The plugin of job.formula from the cache (compiling it first, saying so on standard error), its path into
// job.plugin and its entry into job.formula_cache_key; nothing, with an issue at /model/formula, when it cannot be
// had.
std::optional<formula::CachedPlugin> attach_formula_plugin(Job& job, std::vector<JobIssue>& issues) {
  try {
    formula::CachedPlugin plugin = formula::cached_plugin(
        *job.formula, [](const std::string& line) { std::cerr << "nonsep: " << line << std::endl; });
    job.plugin = plugin.path.string();
    job.formula_cache_key = plugin.key;
    return plugin;
  } catch (const std::exception& error) {
    issues.push_back({"/model/formula", "a formula model that cannot be compiled: " + std::string(error.what()),
                      "a formula model and a working C++ compiler (docs/formula-models.md)"});
    return std::nullopt;
  }
}

std::string gibibytes(std::size_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", static_cast<double>(bytes) / static_cast<double>(std::size_t{1} << 30));
  return text;
}

std::string report(const std::filesystem::path& job_file, const std::vector<JobIssue>& issues) {
  std::string text = "invalid job file " + job_file.string() + " (" + std::to_string(issues.size()) +
                     (issues.size() == 1 ? " problem)" : " problems)");
  for (const auto& issue : issues) text += "\n  " + to_string(issue);
  return text;
}

// The text of the job file, or nothing and an issue at "": no such file, a directory, not readable, or more than
// max_job_file_bytes (known from the size of a regular file; otherwise found by reading one byte past the limit,
// so that a device without end such as /dev/zero is refused too).
std::optional<std::string> read_job_text(const std::filesystem::path& job_file, std::vector<JobIssue>& issues) {
  const std::string limit = "a job file of at most " + std::to_string(max_job_file_bytes) + " bytes (64 MiB)";
  std::error_code error;
  const auto status = std::filesystem::status(job_file, error);
  if (!error && std::filesystem::is_directory(status)) {
    issues.push_back({"", "a directory at " + job_file.string(), "the path of a job file (a JSON file, not a folder)"});
    return std::nullopt;
  }
  if (!error && std::filesystem::is_regular_file(status)) {
    const auto size = std::filesystem::file_size(job_file, error);
    if (!error && size > max_job_file_bytes) {
      issues.push_back({"", "a file of " + std::to_string(size) + " bytes", limit});
      return std::nullopt;
    }
  }
  std::ifstream in(job_file, std::ios::binary);
  std::string text;
  if (in) {
    char buffer[1 << 16];
    while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
      text.append(buffer, static_cast<std::size_t>(in.gcount()));
      if (text.size() > max_job_file_bytes) {
        issues.push_back(
            {"", "more than " + std::to_string(max_job_file_bytes) + " bytes at " + job_file.string(), limit});
        return std::nullopt;
      }
    }
  }
  if (!in.is_open() || in.bad()) {
    issues.push_back({"", "no readable file at " + job_file.string(), "the path of a readable job file"});
    return std::nullopt;
  }
  return text;
}

}  // namespace

InvalidJob::InvalidJob(const std::filesystem::path& job_file, std::vector<JobIssue> issues)
    : std::runtime_error(report(job_file, issues)), issues_(std::move(issues)) {}

std::optional<Job> read_job(const std::filesystem::path& job_file, std::vector<JobIssue>& issues) {
  const auto text = read_job_text(job_file, issues);
  if (!text) return std::nullopt;
  const auto document = parse_job_text(*text, issues);
  if (!document) return std::nullopt;
  return parse_job(*document, job_file, issues);
}

std::optional<LoadedJob> load_model(Job job, std::vector<JobIssue>& issues, std::size_t processes) {
  std::optional<formula::CachedPlugin> cached;
  if (job.formula) {
    // What `nonsep validate` checks without the compiler comes first: a job with any problem compiles nothing.
    check_formula_job(job, issues);
    if (!issues.empty() || !(cached = attach_formula_plugin(job, issues))) return std::nullopt;
  }
  if (job.plugin.empty()) return std::nullopt;
  LoadedJob loaded{std::move(job), {}, {}};
  const Job& checked = loaded.job;
  try {
    // A formula's plugin is loaded through the descriptor of the file the cache checked, not by its path.
    loaded.plugin = cached ? formula::load_cached_plugin(*cached) : load_plugin(checked.plugin, checked.directory);
  } catch (const std::exception& error) {
    issues.push_back({"/model/plugin", "\"" + checked.plugin + "\", which cannot be loaded: " + error.what(),
                      "a plugin name listed by `nonsep models`, or the path of a plugin file"});
    return std::nullopt;
  }
  const std::size_t before = issues.size();
  check_model_parameters(checked.parameters, loaded.plugin.parameters(), issues);
  check_swept_parameters(checked, loaded.plugin.parameters(), issues);
  if (issues.size() != before) return std::nullopt;
  try {
    loaded.model = loaded.plugin.create(checked.parameter_set(0));
  } catch (const std::exception& error) {
    issues.push_back({"/model/parameters",
                      job_reader::describe(checked.parameter_set(0)) + ", refused by the plugin: " + error.what(),
                      "parameters the plugin accepts (see `nonsep inspect " + checked.plugin + "`)"});
    return std::nullopt;
  }
  check_dimension(checked.initial, loaded.model.dimension(), issues);
  // Only the dense path forms n x n Hessians: with Hessian-vector products every evaluation is O(n).
  if (const std::size_t n = loaded.model.dimension();
      loaded.plugin.has_hessians() && !loaded.plugin.has_hessian_vector_products() && n > max_hessian_values / n)
    issues.push_back({"/model",
                      "a model of dimension " + std::to_string(n) + ", whose Hessian (for H) would take " +
                          gibibytes(n * n * sizeof(double)) + " GiB",
                      "a dimension whose n x n Hessian fits in 1 GiB (n <= 11585) when the plugin has Hessians and no "
                      "Hessian-vector products (hvp_T, hvp_V)"});
  if (issues.size() == before) make_trajectories(loaded, issues);
  if (issues.size() == before) check_gradients_at_initial_states(loaded, issues);
  // A model given by H (plugin ABI version 6) is served by the schemes that integrate H itself, in the form it has.
  const bool general = loaded.plugin.general_hamiltonian();
  if (general) check_schemes_for_general_hamiltonian(checked, loaded.plugin.name(), issues);
  if (!checked.is_study())
    if (const Analysis& analysis = checked.run().analysis;
        analysis.tangent_vectors() > 0 && !general && !loaded.plugin.has_hessians())
      issues.push_back({analysis.tangent_key(),
                        "the plugin '" + loaded.plugin.name() + "', which has no Hessians (hessian_T and hessian_V)",
                        "a plugin with Hessians: the tangent map of a step needs T'' and V'' (the SDK provides them "
                        "by automatic differentiation)"});
  // What the run keeps, against the memory this process can take, before anything runs (a share of the
  // trajectories per process under mpirun).
  if (issues.size() == before)
    if (auto issue =
            memory_issue(loaded, (checked.initial.count + processes - 1) / std::max<std::size_t>(1, processes)))
      issues.push_back(*std::move(issue));
  // Comparators integrate H from its gradient: Hessians and third derivatives of the plugin (ABI 3), or a general
  // plugin's grad_H. Chin's schemes split H into T and V: a general plugin has neither.
  const bool has_gradient_of_h = general || (loaded.plugin.has_hessians() && loaded.plugin.has_third_derivatives());
  const auto check_comparator = [&](const IntegratorSpec& spec, const std::string& path) {
    if (!is_comparator(spec.scheme) || has_gradient_of_h) return;
    issues.push_back(
        {path,
         "\"" + spec.scheme + "\" with the plugin '" + loaded.plugin.name() + "', which has " +
             (loaded.plugin.has_hessians() ? "no third derivatives (d3T, d3V)" : "no Hessians (hessian_T, hessian_V)"),
         "a plugin with Hessians and third derivatives (the gradient of H needs both; the SDK provides "
         "them by automatic differentiation), or a Chin scheme (basic, triplet, mpe)"});
  };
  if (checked.is_study()) {
    const auto& integrators = checked.study().integrators;
    for (std::size_t i = 0; i < integrators.size(); ++i)
      check_comparator(integrators[i].spec, "/study/integrators/" + std::to_string(i) + "/scheme");
    if (const auto& reference = checked.study().reference_run)
      check_comparator(reference->spec, "/study/reference_run/scheme");
  } else {
    if (!checked.run().auto_scheme) check_comparator(checked.run().integrator, "/integrator/scheme");
    if (checked.run().auto_scheme && checked.run().auto_scheme->measure == AutoScheme::Measure::energy &&
        !loaded.plugin.has_energy())
      issues.push_back({"/integrator/measure",
                        "\"energy\" with the plugin '" + loaded.plugin.name() + "', which has no Hessians",
                        "\"phase\": the energy H = T_i V_ij T_j needs the Hessians (hessian_T, hessian_V)"});
    for (const auto& indicator : checked.run().analysis.indicators)
      if (indicator->needs().across_flow && !has_gradient_of_h)
        issues.push_back({"/analysis/" + indicator->name(),
                          "true with the plugin '" + loaded.plugin.name() + "', which has " +
                              (loaded.plugin.has_hessians() ? "no third derivatives (d3T, d3V)"
                                                            : "no Hessians (hessian_T, hessian_V)"),
                          "a plugin with Hessians and third derivatives, or one given by H: " + indicator->name() +
                              " measures the tangent vector across the flow J grad H (the SDK provides the "
                              "derivatives by automatic differentiation)"});
    if (checked.run().analysis.tangent_vectors() > 0 && !checked.run().auto_scheme &&
        is_comparator(checked.run().integrator.scheme) && has_gradient_of_h &&
        !loaded.plugin.has_hamiltonian_hessian_products())
      issues.push_back({checked.run().analysis.tangent_key(),
                        "tangent vectors with the comparator scheme \"" + checked.run().integrator.scheme +
                            "\" and the plugin '" + loaded.plugin.name() +
                            "', which has no directional derivative of grad H (hvp_H, plugin ABI version 5; it is of "
                            "version " +
                            std::to_string(loaded.plugin.abi_version()) + ")",
                        "a plugin with hvp_H (rebuild it against the installed SDK, which provides it by automatic "
                        "differentiation), or a Chin scheme (basic, triplet, mpe)"});
  }
  if (issues.size() != before) return std::nullopt;
  return loaded;
}

void check_formula_job(const Job& job, std::vector<JobIssue>& issues) {
  const auto declared = formula::declared_parameters(*job.formula);
  check_model_parameters(job.parameters, declared, issues);
  check_swept_parameters(job, declared, issues);
  check_dimension(job.initial, job.formula->dimension, issues, true);
  if (job.formula->h_tree) check_schemes_for_general_hamiltonian(job, job.formula->name, issues);
}

LoadedJob load_job(const std::filesystem::path& job_file, std::size_t processes) {
  std::vector<JobIssue> issues;
  auto job = read_job(job_file, issues);
  if (!job) throw InvalidJob(job_file, std::move(issues));
  auto loaded = load_model(std::move(*job), issues, processes);
  if (!issues.empty()) throw InvalidJob(job_file, std::move(issues));
  if (!loaded) throw std::logic_error("load_model refused " + job_file.string() + " without saying why");
  return std::move(*loaded);
}

}  // namespace nonsep::host
