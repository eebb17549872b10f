// Every way a plugin can be wrong is refused with its own message (and no crash): missing file, unknown name, not
// a shared library, no entry symbol, ABI version, table size, metadata, create failing, and evaluation failing
// with a status or by throwing inside the plugin.
#include <doctest/doctest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "nonsep/host/plugin_loader.hpp"
#include "nonsep/plugin_abi.h"

namespace test_loader_errors {

using namespace nonsep::host;
namespace fs = std::filesystem;

namespace {

const fs::path test_plugins = NONSEP_TEST_PLUGIN_DIR;
const fs::path build_plugins = NONSEP_BUILD_PLUGIN_DIR;

std::string load_error(const std::string& spec, const fs::path& base = test_plugins) {
  try {
    load_plugin(spec, base);
  } catch (const PluginError& e) {
    return e.what();
  }
  return "(loaded without error)";
}

template <class Error = PluginError>
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Sets NONSEP_PLUGIN_PATH for the lifetime of the object.
struct PluginPathVariable {
  explicit PluginPathVariable(const std::string& value) { ::setenv("NONSEP_PLUGIN_PATH", value.c_str(), 1); }
  ~PluginPathVariable() { ::unsetenv("NONSEP_PLUGIN_PATH"); }
};

}  // namespace

TEST_CASE("the valid hand-written plugin loads, so each defect below is the only reason for its failure") {
  const Plugin plugin = load_plugin("hand_written.so", test_plugins);
  CHECK(plugin.name() == "hand_written");
  CHECK_FALSE(plugin.has_hessians());
  const PluginModel model = plugin.create(nlohmann::json::object());
  const double p[] = {0.25};
  double out[1] = {0.0};
  model.grad_T(p, out, 1);
  CHECK(out[0] == 0.25);
}

TEST_CASE("missing file: the resolved path and what it was relative to") {
  const std::string message = load_error("models/absent.so", "/jobs/run1");
  CHECK(message ==
        "plugin file '/jobs/run1/models/absent.so' does not exist ('models/absent.so' relative to "
        "'/jobs/run1')");
  CHECK(load_error("/nowhere/absent.so") == "plugin file '/nowhere/absent.so' does not exist");
}

TEST_CASE("a plugin path that is a folder, a FIFO or a device is named as such, not as missing") {
  const auto folder = std::filesystem::temp_directory_path() / ("nonsep_loader_kinds_" + std::to_string(::getpid()));
  std::filesystem::create_directories(folder / "a_folder.so");
  REQUIRE(::mkfifo((folder / "fifo.so").c_str(), 0644) == 0);
  CHECK(load_error((folder / "a_folder.so").string()) ==
        "plugin file '" + (folder / "a_folder.so").string() + "' is a folder, not a shared library");
  CHECK(load_error((folder / "fifo.so").string()) ==
        "plugin file '" + (folder / "fifo.so").string() + "' is a FIFO (named pipe), not a shared library");
  for (const char* device : {"/dev/zero", "/dev/null"})
    CHECK(load_error(device) == "plugin file '" + std::string(device) + "' is a device, not a shared library");
  std::filesystem::remove_all(folder);
}

TEST_CASE("unknown name: every folder tried is listed, NONSEP_PLUGIN_PATH first") {
  const PluginPathVariable variable("/nonexistent/first:/nonexistent/second");
  const auto search_path = plugin_search_path();
  REQUIRE(search_path.size() >= 3);
  CHECK(search_path[0] == "/nonexistent/first");
  CHECK(search_path[1] == "/nonexistent/second");
  CHECK(search_path.back() == build_plugins.lexically_normal());
  const std::string message = load_error("no_such_model", "");
  CHECK(contains(message, "plugin 'no_such_model' not found"));
  for (const auto& directory : search_path) CHECK(contains(message, (directory / "no_such_model.so").string()));
}

TEST_CASE("names are found in NONSEP_PLUGIN_PATH before the build tree, paths relative to the job folder") {
  {
    const PluginPathVariable variable(test_plugins.string());
    CHECK(load_plugin("hand_written", "").path() == test_plugins / "hand_written.so");
  }
  CHECK(load_plugin("paper1d", "").path() == build_plugins / "paper1d.so");
  CHECK(load_plugin("../paper1d.so", build_plugins / "CMakeFiles").path() == build_plugins / "paper1d.so");
}

TEST_CASE("not a shared library: the dynamic loader's own text is included") {
  const std::string message = load_error("not_a_library.so");
  CHECK(contains(message, "cannot load '" + (test_plugins / "not_a_library.so").string() + "' as a shared library"));
  CHECK(contains(message, "invalid ELF header"));
}

TEST_CASE("no plugin symbol") {
  const std::string file = (test_plugins / "missing_entry_symbol.so").string();
  CHECK(load_error("missing_entry_symbol.so") ==
        std::string("'").append(file).append(
            "' is a shared library but not a nonsep plugin: it does not export the symbol 'nonsep_plugin' (define "
            "it with NONSEP_EXPORT_MODEL, see plugin_sdk.hpp, or NONSEP_DEFINE_PLUGIN, see plugin_abi.h)"));
}

TEST_CASE("a plugin of ABI version 1 (its entry function, no plugin symbol): expected and found") {
  const std::string file = (test_plugins / "version_1_entry.so").string();
  CHECK(load_error("version_1_entry.so") ==
        "plugin '" + file +
            "' uses plugin ABI version 1 (it exports 'nonsep_plugin_entry') but this host uses "
            "version 6 (expected 6, 5, 4 or 3, found 1); rebuild the plugin against the installed SDK "
            "(find_package(nonsep) "
            "and "
            "nonsep_add_model, or the headers of this nonsep's include/nonsep/plugin_abi.h)");
}

TEST_CASE("a plugin of ABI version 2 (the one with integrate): expected and found, and how to rebuild") {
  const std::string message = load_error("wrong_abi_version.so");
  CHECK(contains(message, "uses plugin ABI version 2 but this host uses version 6 (expected 6, 5, 4 or 3, found 2)"));
  CHECK(contains(message, "rebuild the plugin against the installed SDK"));
}

TEST_CASE("a plugin of ABI version 3 loads: its shorter table, none of version 4's entries read past its end") {
  const Plugin plugin = load_plugin("version_3_table.so", test_plugins);
  CHECK(plugin.name() == "version_3_table");
  CHECK(plugin.abi_version() == 3);
  CHECK(load_plugin("hand_written.so", test_plugins).abi_version() == 6);
  const PluginModel model = plugin.create(nlohmann::json::object());
  const double p[] = {0.5};
  double out[1] = {0.0};
  model.grad_V(p, out, 1);
  CHECK(out[0] == 0.5);
  // The table it was built with holds grad_K past the version-3 size: a loader reading it would refuse the plugin
  // (a capability it does not claim, and grad_K without value_K).
}

TEST_CASE("a version-4 table that ends after chin_steps loads without the energy entries past its end") {
  const Plugin plugin = load_plugin("version_4_kernel_table.so", test_plugins);
  CHECK(plugin.abi_version() == 4);
  // The table it was built with holds energy_TTV past that size: a loader reading it would refuse the plugin (a
  // capability it does not claim).
  CHECK_FALSE(plugin.has_product_energy(nonsep::HamiltonianForm::TTV));
  CHECK_FALSE(plugin.has_product_energy(nonsep::HamiltonianForm::VVT));
  const PluginModel model = plugin.create(nlohmann::json::object());
  CHECK_FALSE(model.has_product_energy(nonsep::HamiltonianForm::TTV));
  const double q[] = {0.5}, p[] = {0.25};
  double out[1] = {0.0};
  CHECK_THROWS_AS(model.product_energy(nonsep::HamiltonianForm::TTV, q, p, out, 1), nonsep::ModelError);
}

TEST_CASE("a version-4 table loads without hvp_H past its end, and its calls are refused naming the entry") {
  const Plugin plugin = load_plugin("version_4_table.so", test_plugins);
  CHECK(plugin.abi_version() == 4);
  // The table it was built with holds hvp_H past version 4's size: a loader reading it would refuse the plugin (a
  // capability it does not claim).
  CHECK_FALSE(plugin.has_hamiltonian_hessian_products());
  const PluginModel model = plugin.create(nlohmann::json::object());
  CHECK_FALSE(model.has_hamiltonian_hessian_products());
  const double q[] = {0.5}, p[] = {0.25}, dq[] = {1.0}, dp[] = {0.0};
  double out_q[1] = {0.0}, out_p[1] = {0.0};
  try {
    model.hvp_H(nonsep::HamiltonianForm::TTV, q, p, dq, dp, out_q, out_p, 1);
    FAIL("hvp_H of a plugin without it did not throw");
  } catch (const nonsep::ModelError& e) {
    CHECK(contains(e.what(), "plugin 'version_4_table' does not provide hvp_H"));
  }
  // Version 4's struct sizes: the whole table and its first edition; a version-4 table of version 5's size is refused.
  CHECK(NONSEP_PLUGIN_V4_STRUCT_SIZE + 2 * sizeof(void*) == NONSEP_PLUGIN_V5_STRUCT_SIZE);  // hvp_H, chin_tangent_steps
}

TEST_CASE("an hvp_H the metadata does not claim") {
  CHECK(contains(load_error("unclaimed_hvp_H.so"),
                 "says capability \"hvp_H\" is false but the table's hvp_H pointer is set"));
}

TEST_CASE("a separable part without its value: the energy of H needs it") {
  const std::string message = load_error("grad_U_without_value_U.so");
  CHECK(contains(message, "gives grad_U but not value_U: the energy of H = T_i V_ij T_j + K + U needs U itself"));
}

TEST_CASE("a part's Hessian-vector product without its gradient") {
  const std::string message = load_error("hvp_K_without_grad_K.so");
  CHECK(contains(message, "gives the value, Hessian or Hessian-vector product of K but not grad_K"));
}

TEST_CASE("the table itself exported under the symbol, not a pointer to it: refused before reading through it") {
  const std::string message = load_error("table_not_pointer.so");
  CHECK(contains(message, "the symbol 'nonsep_plugin' of plugin '" + (test_plugins / "table_not_pointer.so").string() +
                              "' does not point to a table in a loaded library (it holds 0x"));
  CHECK(contains(message, "not the table itself"));
}

TEST_CASE("wrong table size: expected and found") {
  const std::size_t expected = sizeof(nonsep_plugin_api), found = expected - 2 * sizeof(void*);
  const std::string message = load_error("wrong_table_size.so");
  CHECK(contains(message, "(expected " + std::to_string(expected) + ", found " + std::to_string(found) + ")"));
  CHECK(contains(message, "has a function table of " + std::to_string(found) + " bytes"));
  // Version 6 has two sizes: with gauss_steps, and its edition that ends before it.
  CHECK(contains(message, "ABI version 6 defines " + std::to_string(expected) + " or " +
                              std::to_string(NONSEP_PLUGIN_V6_EVALUATION_STRUCT_SIZE) + " (expected"));
}

TEST_CASE("a version-6 table that ends before gauss_steps loads, and its Gauss steps go through the evaluations") {
  const Plugin plugin = load_plugin("version_6_evaluation_table.so", test_plugins);
  CHECK(plugin.abi_version() == 6);
  // The table it was built with holds gauss_steps past that size: a loader reading it would use it.
  const PluginModel model = plugin.create(nlohmann::json::object()).with_kernel();
  CHECK_FALSE(model.has_gauss_kernel());
  CHECK(NONSEP_PLUGIN_V6_EVALUATION_STRUCT_SIZE + sizeof(void*) == sizeof(nonsep_plugin_api));
}

TEST_CASE("metadata that is not valid JSON") {
  const std::string message = load_error("invalid_metadata_json.so");
  CHECK(contains(message, "the metadata of plugin '" + (test_plugins / "invalid_metadata_json.so").string() +
                              "' is not valid JSON: [json.exception.parse_error"));
  CHECK(contains(message, "(metadata begins: \"{\"name\": \"invalid_metadata_json\", \"version\": \")"));
}

TEST_CASE("metadata whose name is not the file's") {
  CHECK(contains(load_error("metadata_names_another.so"),
                 "declares the name 'someone_else' but the file is named metadata_names_another.so; a plugin's "
                 "file must be <name>.so (expected 'metadata_names_another', found 'someone_else')"));
}

TEST_CASE("a required function missing from the table") {
  CHECK(contains(load_error("missing_grad_V.so"), "lacks the required function grad_V (its table entry is null)"));
}

TEST_CASE("capabilities that disagree with the table") {
  CHECK(contains(load_error("capability_mismatch.so"),
                 "says capability \"hessian_T\" is true but the table's hessian_T pointer is null"));
  CHECK(contains(load_error("claims_absent_d3T.so"),
                 "says capability \"d3T\" is true but the table's d3T pointer is null"));
  CHECK(
      contains(load_error("unclaimed_d3V.so"), "says capability \"d3V\" is false but the table's d3V pointer is set"));
}

TEST_CASE("metadata without \"thread_safe\" (required since ABI version 3)") {
  CHECK(contains(load_error("metadata_without_thread_safe.so"),
                 "the metadata of plugin '" + (test_plugins / "metadata_without_thread_safe.so").string() +
                     "' lacks the boolean \"thread_safe\" (required since plugin ABI version 3"));
  CHECK(load_plugin("hand_written.so", test_plugins).thread_safe());
  // A plugin with global mutable state says so, and loads.
  const Plugin global_state = load_plugin("global_state.so", test_plugins);
  CHECK_FALSE(global_state.thread_safe());
  const double q[] = {2.0};
  double out[1];
  global_state.create(nlohmann::json::object()).grad_V(q, out, 1);
  CHECK(out[0] > 0.0);
}

TEST_CASE("create failing inside the plugin: its message names the parameter") {
  const Plugin plugin = load_plugin("create_failing.so", test_plugins);
  CHECK(plugin.create({{"inner_radius", 1.5}}).dimension() == 1);
  const std::string message = error_of([&] { plugin.create({{"inner_radius", 3.0}}); });
  CHECK(contains(message,
                 "could not create a model (invalid parameters): parameter 'inner_radius' must be "
                 "smaller than 'outer_radius'"));
}

TEST_CASE("parameters refused by the host before create(), each naming the parameter") {
  const Plugin radial = load_plugin("radial", "");
  CHECK(contains(error_of([&] {
                   radial.create({{"dimension", 17}});
                 }),
                 "parameter 'dimension' = 17 is above its maximum 16"));
  CHECK(contains(error_of([&] {
                   radial.create({{"dimension", 2.5}});
                 }),
                 "parameter 'dimension' must be an integer (found 2.5)"));
  CHECK(contains(error_of([&] {
                   radial.create({{"dimenson", 3}});
                 }),
                 "unknown parameter 'dimenson' (known parameters: dimension)"));
  CHECK(contains(error_of([&] { radial.create(nlohmann::json::array()); }), "the parameters must be a JSON object"));
  CHECK(contains(error_of([&] {
                   load_plugin("quadratic_kinetic", "").create({{"lambda", "big"}});
                 }),
                 "parameter 'lambda' must be a number (found \"big\")"));
  CHECK(contains(error_of([&] {
                   load_plugin("paper1d", "").create({{"lambda", 1}});
                 }),
                 "unknown parameter 'lambda' (this model has no parameters)"));
  CHECK(radial.create({{"dimension", 16}}).parameters() == nlohmann::json{{"dimension", 16}});
  CHECK(radial.create(nlohmann::json::object()).dimension() == 2);
  CHECK(radial.create({}).dimension() == 2);  // {} is a JSON null for nlohmann::json: no parameters
}

TEST_CASE("an evaluation returning an error status becomes a ModelError with the plugin's message") {
  const PluginModel model = load_plugin("evaluation_fails.so", test_plugins).create(nlohmann::json::object());
  const double inside[] = {0.5}, outside[] = {1.5};
  double out[1];
  model.grad_V(inside, out, 1);
  CHECK(out[0] == doctest::Approx(4.0 / 3.0));
  CHECK(error_of<nonsep::ModelError>([&] { model.grad_V(outside, out, 1); }) ==
        "plugin 'evaluation_fails' failed in grad_V (evaluation failed): V = -log(1 - q^2) needs |q| < 1 (found q = "
        "1.500000)");
  // Not a failure: V = -log(1 - q^2) is NaN at q = 1.5, so its automatic Hessian is NaN too, returned as a number.
  out[0] = 0.0;
  model.hessian_V(outside, out, 1);
  CHECK(std::isnan(out[0]));
}

TEST_CASE("an exception thrown inside the plugin is caught there and becomes a ModelError") {
  const PluginModel model = load_plugin("evaluation_throws.so", test_plugins).create(nlohmann::json::object());
  const double p[] = {0.5};
  double out[1];
  CHECK(error_of<nonsep::ModelError>([&] { model.grad_T(p, out, 1); }) ==
        "plugin 'evaluation_throws' failed in grad_T (internal error): exception in grad_T: deliberate bug: index 7 "
        "out of range in grad_T");
  model.grad_V(p, out, 1);  // the instance is still usable
  CHECK(out[0] == 0.5);
}

TEST_CASE("an optional function the plugin lacks, and a batch that does not fit") {
  const PluginModel model = load_plugin("hand_written.so", test_plugins).create(nlohmann::json::object());
  const double x[] = {0.5, 0.25};
  double out[4];
  CHECK(error_of<nonsep::ModelError>([&] { model.hessian_T(x, out, 1); }) ==
        "plugin 'hand_written' does not provide hessian_T (its capability is false)");
  CHECK_FALSE(model.plugin().has_third_derivatives());
  CHECK(error_of<nonsep::ModelError>([&] { model.d3T(x, x, out, 1); }) ==
        "plugin 'hand_written' does not provide d3T (its capability is false)");
  CHECK(contains(error_of<nonsep::InvalidArgument>([&] { model.d3V(x, std::span(x, 1), out, 2); }),
                 "d3V: a batch of 2 states of dimension 1 needs 2 direction components (found 1)"));
  CHECK(contains(error_of<nonsep::InvalidArgument>([&] { model.grad_T(std::span(x, 1), out, 2); }),
                 "grad_T: a batch of 2 states of dimension 1 needs 2 inputs and 2 outputs (found 1 and 4)"));
}

TEST_CASE("discovery lists good plugins and the failures with their errors, first of each name winning") {
  const PluginPathVariable variable(test_plugins.string());
  const auto found = discover_plugins();
  auto entry = [&](const std::string& stem) -> const DiscoveredPlugin* {
    for (const auto& d : found)
      if (d.path.stem() == stem) return &d;
    return nullptr;
  };
  REQUIRE(entry("paper1d") != nullptr);
  CHECK(entry("paper1d")->plugin.has_value());
  REQUIRE(entry("wrong_abi_version") != nullptr);
  CHECK_FALSE(entry("wrong_abi_version")->plugin.has_value());
  CHECK(contains(entry("wrong_abi_version")->error, "(expected 6, 5, 4 or 3, found 2)"));
  REQUIRE(entry("not_a_library") != nullptr);
  CHECK(contains(entry("not_a_library")->error, "invalid ELF header"));
  CHECK(entry("hand_written")->path == test_plugins / "hand_written.so");
}

TEST_CASE("a version-5 table loads without value_H and grad_H past its end, as a product-form model") {
  const Plugin plugin = load_plugin("version_5_table.so", test_plugins);
  CHECK(plugin.abi_version() == 5);
  CHECK_FALSE(plugin.general_hamiltonian());
  // The table it was built with holds value_H past version 5's size: a loader reading it would refuse the plugin.
  const PluginModel model = plugin.create(nlohmann::json::object());
  const double q[] = {0.5}, p[] = {0.25};
  double out[1] = {0.0};
  model.grad_V(q, out, 1);
  CHECK(out[0] == 0.5);
  try {
    model.value_H(q, p, out, 1);
    FAIL("value_H of a product-form plugin did not throw");
  } catch (const nonsep::ModelError& e) {
    CHECK(contains(e.what(), "plugin 'version_5_table' does not provide value_H"));
  }
  CHECK(NONSEP_PLUGIN_V5_STRUCT_SIZE + 2 * sizeof(void*) ==
        NONSEP_PLUGIN_V6_EVALUATION_STRUCT_SIZE);  // value_H, grad_H
}

TEST_CASE("a model given by H: its required entries, and no entry of the product form") {
  CHECK(contains(load_error("general_without_grad_H.so"),
                 "lacks the required function grad_H (its table entry is null), which a model given by H "
                 "(\"hamiltonian_form\": \"general\") needs"));
  CHECK(contains(load_error("general_with_grad_T.so"),
                 "says \"hamiltonian_form\": \"general\" but the table's grad_T pointer is set"));
  CHECK(contains(load_error("product_with_value_H.so"),
                 "has value_H or grad_H in its table, which only a model given by H has"));
  const Plugin plugin = load_plugin("general_hand_written.so", test_plugins);
  CHECK(plugin.general_hamiltonian());
  CHECK(plugin.has_energy());
  CHECK_FALSE(plugin.has_hessians());
  const PluginModel model = plugin.create(nlohmann::json::object());
  CHECK(model.general_hamiltonian());
  const double q[] = {0.5, -1.0}, p[] = {0.25, 2.0};
  double h[2] = {}, dq[2] = {}, dp[2] = {};
  model.value_H(q, p, h, 2);
  model.grad_H(q, p, dq, dp, 2);
  CHECK(h[1] == 2.5);
  CHECK(dq[1] == -1.0);
  CHECK(dp[0] == 0.25);
  CHECK_THROWS_AS(model.grad_T(p, dq, 1), nonsep::ModelError);
}

}  // namespace test_loader_errors
