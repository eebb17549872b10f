// The `nonsep` commands and options around a run: output folders, validate, usage and --help, models, inspect.
#include <doctest/doctest.h>

#include <filesystem>
#include <set>
#include <string>

#include "host_run_support.hpp"

namespace test_host_commands {

using nlohmann::json;
using namespace nonsep::host_testing;

TEST_CASE("the default output folder is <job>.out beside the job file, --output overrides it") {
  TemporaryFolder folder;
  json job = quickstart_job();
  job.erase("output");
  const auto file = write_job(folder / "orbit.json", job);
  CHECK(run_nonsep({"run", "--quiet", file.string()}, folder.path()).status == 0);
  CHECK(std::filesystem::exists(folder / "orbit.out" / "summary.json"));
  CHECK(std::filesystem::exists(folder / "orbit.out" / "trajectory.csv"));
  job["output"] = {{"directory", "results/a"}};
  write_job(file, job);
  CHECK(run_nonsep({"run", "--quiet", file.string()}, folder.path()).status == 0);
  CHECK(std::filesystem::exists(folder / "results" / "a" / "summary.json"));
  // The results, the folder's lock and manifest (output/run_folder.hpp), and no temporary file of an atomic write.
  std::set<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder / "results" / "a"))
    files.insert(entry.path().filename().string());
  CHECK(files == std::set<std::string>{".nonsep-run.json", ".nonsep.lock", "summary.json", "trajectories.csv",
                                       "trajectory.csv"});
}

TEST_CASE("an output folder that cannot be created is invalid input: exit 2") {
  TemporaryFolder folder;
  write_text(folder / "blocker", "a file, not a folder");
  const auto file = write_job(folder / "job.json", quickstart_job());
  const auto result =
      run_nonsep({"run", "--quiet", "--output", (folder / "blocker" / "out").string(), file.string()}, folder.path());
  CHECK(result.status == 2);
  CHECK(result.err.find("blocker") != std::string::npos);
}

TEST_CASE("an empty --output is an error (exit 2), not the default folder, for run, example and model compile") {
  TemporaryFolder folder;
  json job = quickstart_job();
  job.erase("output");
  const auto file = write_job(folder / "orbit.json", job);
  for (const std::vector<std::string>& command :
       {std::vector<std::string>{"run", "--quiet", "--output", "", file.string()},
        std::vector<std::string>{"run", "--quiet", "-o", "", file.string()},
        std::vector<std::string>{"example", "--output", ""},
        std::vector<std::string>{"model", "compile", file.string(), "-o", ""}}) {
    CAPTURE(command[0]);
    const auto result = run_nonsep(command, folder.path());
    CHECK(result.status == 2);
    CHECK(result.err.find("an empty path names no file or folder") != std::string::npos);
  }
  CHECK(!std::filesystem::exists(folder / "orbit.out"));
}

TEST_CASE("validate checks without running, errors go to stderr with exit 2") {
  TemporaryFolder folder;
  const auto file = write_job(folder / "job.json", quickstart_job());
  auto result = run_nonsep({"validate", file.string()}, folder.path());
  CHECK(result.status == 0);
  CHECK(result.out.find("valid:") != std::string::npos);
  CHECK(result.out.find("78 steps") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(folder / "quickstart.out"));
  json job = quickstart_job();
  job["model"] = {{"plugin", "radial"}, {"parameters", {{"dimension", 3}}}};
  write_job(file, job);
  result = run_nonsep({"validate", file.string()}, folder.path());
  CHECK(result.status == 2);
  CHECK(result.err.find("/initial/q: found 1 component;") != std::string::npos);
}

TEST_CASE("usage: --version, --help with the schemes, options and exit statuses, usage errors exit 2") {
  TemporaryFolder folder;
  auto result = run_nonsep({"--version"}, folder.path());
  CHECK(result.status == 0);
  CHECK(result.out.rfind("nonsep ", 0) == 0);
  // `nonsep --help` describes every scheme with its options; `run --help` names them and points there.
  for (const std::vector<std::string>& args : {std::vector<std::string>{"--help"}, {"run", "--help"}}) {
    result = run_nonsep(args, folder.path());
    CHECK(result.status == 0);
    const bool whole = args.size() == 1;
    for (const auto& scheme : nonsep::scheme_catalogue()) {
      if (!whole) {
        CHECK(result.out.find(scheme.name + (&scheme == &nonsep::scheme_catalogue().back() ? " (" : ", ")) !=
              std::string::npos);
        continue;
      }
      CHECK(result.out.find("  " + scheme.name + " [family " + scheme.family + "]: " + scheme.method) !=
            std::string::npos);
      for (const auto& parameter : scheme.parameters)
        CHECK(result.out.find(parameter.name + " (default " + parameter.default_text + ")") != std::string::npos);
    }
    if (!whole) CHECK(result.out.find("`nonsep --help` describes each") != std::string::npos);
    for (const char* status : {"  0 ", "  1 ", "  2 ", "  130 "}) CHECK(result.out.find(status) != std::string::npos);
  }
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{}, {"run"}, {"frobnicate"}, {"run", "a", "b"}, {"inspect", "paper1d", "--nope"}}) {
    CHECK(run_nonsep(args, folder.path()).status == 2);
  }
  const auto unknown = run_nonsep({"frobnicate", "job.json"}, folder.path());
  CHECK(unknown.err.find("unknown command 'frobnicate'; the commands are run, validate, inspect, models, example, "
                         "schema and model") != std::string::npos);
  for (const char* command : {"models", "example"}) CHECK(unknown.err.find(command) != std::string::npos);
}

TEST_CASE("number options take finite numbers in their range: --progress-every nan, inf or -1 is a usage error") {
  TemporaryFolder folder;
  const auto job = write_job(folder / "job.json", quickstart_job());
  for (const char* bad : {"nan", "inf", "-1", "1e400"}) {
    CAPTURE(bad);
    const auto result = run_nonsep({"run", "--quiet", "--progress-every", bad, job.string()}, folder.path());
    CHECK(result.status == 2);
    CHECK(result.err.find("\"" + std::string(bad) + "\" is not a finite number >= 0") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(folder / "job.out"));
  }
  const auto tolerance = run_nonsep({"inspect", "paper1d", "--check", "--tolerance", "nan"}, folder.path());
  CHECK(tolerance.status == 2);
  CHECK(tolerance.err.find("\"nan\" is not a finite number > 0") != std::string::npos);
  CHECK(run_nonsep({"run", "--quiet", "--progress-every", "0", job.string()}, folder.path()).status == 0);
}

TEST_CASE("models lists every plugin on the search path, one line each") {
  TemporaryFolder folder;
  const auto result = run_nonsep({"models"}, folder.path());
  CHECK(result.status == 0);
  for (const char* name :
       {"paper1d", "radial", "quadratic_kinetic", "tao_product", "blowup", "blowup_gradients_only"}) {
    CAPTURE(name);
    const auto at = result.out.find(std::string(name) + "  ");
    REQUIRE(at != std::string::npos);
    const auto line = result.out.substr(at, result.out.find('\n', at) - at);
    CHECK(line.find(std::string(name) + ".so") != std::string::npos);
    CHECK(line.find("dimension") != std::string::npos);
  }
}

TEST_CASE("inspect shows the metadata, --json the raw metadata, --check the derivative check") {
  TemporaryFolder folder;
  auto result = run_nonsep({"inspect", "radial"}, folder.path());
  CHECK(result.status == 0);
  CHECK(result.out.find("dimension integer 2") != std::string::npos);
  CHECK(result.out.find("[1, 16]") != std::string::npos);

  result = run_nonsep({"inspect", "paper1d", "--json"}, folder.path());
  CHECK(result.status == 0);
  CHECK(json::parse(result.out)["name"] == "paper1d");

  for (const char* good : {"paper1d", "radial", "blowup"}) {
    CAPTURE(good);
    result = run_nonsep({"inspect", good, "--check"}, folder.path());
    CHECK(result.status == 0);
    CHECK(result.out.find("derivative check passed") != std::string::npos);
    CHECK(result.out.find("threads: two instances on two threads give the numbers of one thread") != std::string::npos);
  }
  // The SDK's plugins have third derivatives, checked against differences of the Hessians.
  result = run_nonsep({"inspect", "radial", "--check"}, folder.path());
  CHECK(result.out.find("skipped") == std::string::npos);
  result = run_nonsep({"inspect", "blowup", "--check"}, folder.path());
  CHECK(result.out.find("skipped: third derivatives: the plugin has no d3T/d3V") != std::string::npos);
  // Global mutable state: declared, the two-thread check is skipped; undeclared, it is caught.
  const std::string broken = NONSEP_BROKEN_PLUGIN_DIR;
  result = run_nonsep({"inspect", broken + "/global_state.so", "--check"}, folder.path());
  CHECK(result.status == 0);
  CHECK(result.out.find("threads: skipped: the plugin declares \"thread_safe\": false") != std::string::npos);
  result = run_nonsep({"inspect", broken + "/global_state_claims_safe.so", "--check"}, folder.path());
  CHECK(result.status == 1);
  CHECK(result.out.find("threads FAILED: grad_V[0] of a batch of 16 is ") != std::string::npos);
  CHECK(result.out.find("the plugin must declare \"thread_safe\": false") != std::string::npos);
  result = run_nonsep({"inspect", "blowup_wrong_hessian", "--check"}, folder.path());
  CHECK(result.status == 1);
  CHECK(result.out.find("derivative check FAILED") != std::string::npos);
  CHECK(result.out.find("  hessian_V[0] at q = (") != std::string::npos);
  // The separable part K(p) + U(q) is checked too: a wrong grad U is named, a right one passes.
  result = run_nonsep({"inspect", "wrong_grad_U", "--check"}, folder.path());
  CHECK(result.status == 1);
  CHECK(result.out.find("  grad_U[0] at q = (") != std::string::npos);
  result = run_nonsep({"inspect", "mathews_lakshmanan", "--check"}, folder.path());
  CHECK(result.status == 0);
  CHECK(result.out.find("derivative check passed") != std::string::npos);
  // A written-out product term of H is compared with H from the products: a wrong one fails, a right one passes.
  result = run_nonsep({"inspect", "wrong_energy", "--check"}, folder.path());
  CHECK(result.status == 1);
  const auto line = [&](const std::string& start) {
    const auto at = result.out.find(start);
    return at == std::string::npos ? std::string() : result.out.substr(at, result.out.find('\n', at) - at);
  };
  CHECK(line("energy_TTV (written out)").ends_with("(relative to max(1, |H|)): FAILED, above the tolerance"));
  CHECK(line("energy_VVT (written out)").ends_with("(relative to max(1, |H|))"));
  // hvp_H of a product-form plugin against differences of grad H: a wrong written-out d4V fails in TTV, which takes
  // it, and passes in VVT; paper1d's (every derivative written out) passes both.
  result = run_nonsep({"inspect", "wrong_fourth", "--check"}, folder.path());
  CHECK(result.status == 1);
  CHECK(line("hvp_H (TTV) against differences of grad H").ends_with("FAILED, above the tolerance"));
  CHECK(line("hvp_H (VVT) against differences of grad H").ends_with("(relative to max(1, |d|))"));
  result = run_nonsep({"inspect", "paper1d", "--check"}, folder.path());
  CHECK(result.status == 0);
  CHECK(line("hvp_H (TTV) against differences of grad H").ends_with("(relative to max(1, |d|))"));
  CHECK(line("hvp_H (VVT) against differences of grad H").ends_with("(relative to max(1, |d|))"));
  result = run_nonsep({"inspect", "lattice_chain", "--check"}, folder.path());
  CHECK(result.status == 0);
  CHECK(result.out.find("  energy:      available (the plugin has both Hessians; writes out H_TTV and H_VVT, one "
                        "pass)\n") != std::string::npos);
  CHECK(result.out.find("energy_TTV (written out) against the products or Hessians") != std::string::npos);
  CHECK(result.out.find("derivative check passed") != std::string::npos);

  result = run_nonsep({"inspect", "no_such_plugin"}, folder.path());
  CHECK(result.status == 2);
  CHECK(result.err.find("no_such_plugin") != std::string::npos);
}

TEST_CASE("a closed standard output is a write error with exit 1, not death by SIGPIPE") {
  TemporaryFolder folder;
  use_test_plugins();
  int ends[2];
  REQUIRE(::pipe(ends) == 0);
  ::close(ends[0]);  // nobody will read
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, ends[1], 1);
  const auto err = folder / "stderr.txt";
  posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::string program = NONSEP_EXECUTABLE, command = "models";
  char* argv[] = {program.data(), command.data(), nullptr};
  pid_t pid = -1;
  REQUIRE(posix_spawn(&pid, NONSEP_EXECUTABLE, &actions, nullptr, argv, environ) == 0);
  posix_spawn_file_actions_destroy(&actions);
  ::close(ends[1]);
  int status = 0;
  REQUIRE(::waitpid(pid, &status, 0) == pid);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 1);
  CHECK(read_text(err).find("cannot write to standard output") != std::string::npos);
}

}  // namespace test_host_commands
