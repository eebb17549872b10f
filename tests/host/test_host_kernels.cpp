// The plugins' stepping kernels in the `nonsep` executable: runs through the kernel (NONSEP_INSTRUCTION_SET=
// baseline) write byte for byte the files of runs through the evaluation path (NONSEP_INSTRUCTION_SET=evaluation),
// for every Chin scheme (mpe of 2 and 3 terms) and form, 1, 5 and 300 states, 1 and 2 threads, states that fail or
// diverge partway, and a run killed and resumed; the tangent kernel likewise for Lyapunov exponents, MEGNO, SALI and
// GALI (basic and triplet, 1 and 4 vectors); summary.json says which path ran; inspect shows and checks the kernels;
// a plugin of another kernel version, and one without kernels, run through the evaluation path; Gauss-Legendre
// through the plugins' gauss_steps likewise (both forms, a model given by H, a Lyapunov vector, a failing state).
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

#include "host_run_support.hpp"
#include "nonsep/core/kernel/chin_kernel.hpp"

namespace test_host_kernels {

using nlohmann::json;
using namespace nonsep::host_testing;

namespace {

// Sets NONSEP_INSTRUCTION_SET for the runs started in its lifetime, then puts the tests' pin back.
struct InstructionSet {
  explicit InstructionSet(const char* name) { ::setenv("NONSEP_INSTRUCTION_SET", name, 1); }
  ~InstructionSet() { ::setenv("NONSEP_INSTRUCTION_SET", "baseline", 1); }
  InstructionSet(const InstructionSet&) = delete;
  InstructionSet& operator=(const InstructionSet&) = delete;
};

struct RunFiles {
  int status = -1;
  std::string trajectories, trajectory, err;
  json summary;
};

RunFiles run_with(const char* instruction_set, const TemporaryFolder& folder, const std::string& name,
                  const std::filesystem::path& file, const char* threads = "1") {
  InstructionSet pin(instruction_set);
  const auto out = folder / name;
  const auto result =
      run_nonsep({"run", "--quiet", "--threads", threads, "--output", out.string(), file.string()}, folder.path());
  RunFiles files{result.status, read_text(out / "trajectories.csv"), "", result.err,
                 comparable(read_json(out / "summary.json"))};
  if (std::filesystem::exists(out / "trajectory.csv")) files.trajectory = read_text(out / "trajectory.csv");
  return files;
}

// The two runs agree byte for byte, but for the summary's "stepping", which says which path ran.
void check_same_files(RunFiles kernel, RunFiles evaluation) {
  INFO("stderr (kernel): " << kernel.err);
  INFO("stderr (evaluation): " << evaluation.err);
  CHECK(kernel.status == evaluation.status);
  CHECK(kernel.trajectories == evaluation.trajectories);
  CHECK(kernel.trajectory == evaluation.trajectory);
  CHECK(kernel.summary["stepping"]["path"] == "kernel");
  CHECK(kernel.summary["stepping"]["instruction_set"] == "x86-64");
  CHECK(evaluation.summary["stepping"]["path"] == "evaluation");
  kernel.summary.erase("stepping");
  evaluation.summary.erase("stepping");
  CHECK(kernel.summary == evaluation.summary);
}

json states(std::size_t count) {
  json list = json::array();
  for (std::size_t i = 0; i < count; ++i) list.push_back(state(0.3 + 0.002 * double(i), 0.2 - 0.001 * double(i)));
  return list;
}

}  // namespace

TEST_CASE(
    "kernel path: every Chin scheme and form, 1, 5 and 300 states, 1 and 2 threads, the evaluation path's files") {
  TemporaryFolder folder;
  for (const json& integrator : {json{{"scheme", "basic"}}, json{{"scheme", "triplet"}, {"order", "4/3"}},
                                 json{{"scheme", "mpe"}, {"order", "4/3"}}, json{{"scheme", "mpe"}, {"order", "2"}}})
    for (const char* form : {"TTV", "VVT"})
      for (std::size_t count : {std::size_t{1}, std::size_t{5}, std::size_t{300}}) {
        json job = paper1d_job(states(count), {{"dt", 0.01}, {"steps", 40}}, integrator);
        job["hamiltonian"] = form;
        job["output"] = {{"every", 10}};
        std::string order = integrator.value("order", "2/3");
        std::replace(order.begin(), order.end(), '/', '_');
        const std::string name =
            integrator["scheme"].get<std::string>() + "-" + order + "-" + form + "-" + std::to_string(count);
        CAPTURE(name);
        const auto file = write_job(folder / (name + ".json"), job);
        for (const char* threads : {"1", "2"}) {
          if (count < 300 && std::string(threads) == "2") continue;  // one block: the threads have nothing to share
          CAPTURE(threads);
          check_same_files(run_with("baseline", folder, name + "-kernel-" + threads, file, threads),
                           run_with("evaluation", folder, name + "-evaluation-" + threads, file, threads));
        }
      }
}

TEST_CASE("tangent kernel: Lyapunov exponents, MEGNO, SALI and GALI, the evaluation path's files") {
  TemporaryFolder folder;
  const json analyses[] = {
      {{"lyapunov", {{"vectors", 1}, {"renormalize_every", 7}, {"every", 10}}}},
      {{"lyapunov", {{"vectors", 1}, {"renormalize_every", 3}, {"every", 10}}}, {"megno", true}},
      {{"lyapunov", {{"vectors", 2}, {"renormalize_every", 5}, {"every", 20}}}, {"sali", true}, {"gali", 2}}};
  for (const json& integrator : {json{{"scheme", "basic"}}, json{{"scheme", "triplet"}, {"order", "4/3"}}})
    for (std::size_t a = 0; a < std::size(analyses); ++a)
      for (const char* form : {"TTV", "VVT"}) {
        json job = paper1d_job(states(70), {{"dt", 0.01}, {"steps", 45}}, integrator);
        job["hamiltonian"] = form;
        job["output"] = {{"every", 15}};
        job["analysis"] = analyses[a];
        const std::string name =
            "tangent-" + integrator["scheme"].get<std::string>() + "-" + std::to_string(a) + "-" + form;
        CAPTURE(name);
        const auto file = write_job(folder / (name + ".json"), job);
        for (const char* threads : {"1", "2"}) {
          CAPTURE(threads);
          const auto kernel = run_with("baseline", folder, name + "-kernel-" + threads, file, threads);
          const auto evaluation = run_with("evaluation", folder, name + "-evaluation-" + threads, file, threads);
          CHECK(read_text(folder / (name + "-kernel-" + threads) / "lyapunov.csv") ==
                read_text(folder / (name + "-evaluation-" + threads) / "lyapunov.csv"));
          check_same_files(kernel, evaluation);
        }
      }
}

TEST_CASE("kernel path: states that fail or diverge partway are reported as the evaluation path reports them") {
  TemporaryFolder folder;
  use_test_plugins();
  // evaluation_fails: grad V refuses |q| >= 1 (a failure inside the kernel, then the evaluation path's replay).
  json failing = json::array();
  for (int i = 0; i < 40; ++i) failing.push_back(state(0.3 + 0.0175 * i, 0.05));
  for (const char* scheme : {"triplet", "mpe"}) {
    CAPTURE(scheme);
    json job = {{"model", {{"plugin", std::string(NONSEP_BROKEN_PLUGIN_DIR) + "/evaluation_fails.so"}}},
                {"integrator", {{"scheme", scheme}, {"order", "4/3"}}},
                {"initial", failing},
                {"time", {{"dt", 0.01}, {"steps", 60}}},
                {"output", {{"every", 10}}}};
    const auto file = write_job(folder / (std::string(scheme) + "-failing.json"), job);
    const auto kernel = run_with("baseline", folder, std::string(scheme) + "-failing-kernel", file, "2");
    check_same_files(kernel, run_with("evaluation", folder, std::string(scheme) + "-failing-evaluation", file, "2"));
    CHECK(kernel.trajectories.find("failed") != std::string::npos);
    CHECK(kernel.trajectories.find("completed") != std::string::npos);
  }
  // paper1d: a state whose gradient overflows diverges in its first step, among states that go on.
  json diverging = states(20);
  diverging[7] = state(0.5, 1e200);
  const auto file = write_job(folder / "diverging.json", paper1d_job(diverging, {{"dt", 0.01}, {"steps", 30}},
                                                                     {{"scheme", "mpe"}, {"order", "4/3"}}));
  const auto diverged = run_with("baseline", folder, "diverging-kernel", file);
  check_same_files(diverged, run_with("evaluation", folder, "diverging-evaluation", file));
  CHECK(diverged.trajectories.find("diverged") != std::string::npos);
}

TEST_CASE("kernel path: a run killed and resumed gives the uninterrupted evaluation path's files") {
  TemporaryFolder folder;
  json job = paper1d_job(states(2000), {{"dt", 0.0001}, {"steps", 200000}}, {{"scheme", "basic"}});
  job["output"] = {{"every", 0}};
  job["checkpoint"] = {{"every_steps", 10000}, {"every_seconds", 0}};
  const auto file = write_job(folder / "job.json", job);
  const auto reference = run_with("evaluation", folder, "reference", file);
  REQUIRE(reference.status == 0);
  InstructionSet pin("baseline");
  const auto step = kill_after_checkpoint(file, folder / "out", 20000, folder.path());
  INFO("killed after the checkpoint at step " << step);
  CHECK(step < 200000);
  const auto resumed =
      run_nonsep({"run", "--quiet", "--resume", "--output", (folder / "out").string(), file.string()}, folder.path());
  INFO("stderr: " << resumed.err);
  REQUIRE(resumed.status == 0);
  CHECK(read_text(folder / "out/trajectories.csv") == reference.trajectories);
  CHECK(read_json(folder / "out/summary.json")["stepping"]["path"] == "kernel");
}

TEST_CASE("kernel path: a plugin without kernels, or of another kernel version, runs through the evaluation path") {
  TemporaryFolder folder;
  use_test_plugins();
  for (const auto& [plugin, note] : {std::pair{std::string("blowup"), std::string("no stepping kernels")},
                                     std::pair{std::string(NONSEP_BROKEN_PLUGIN_DIR) + "/kernel_other_version.so",
                                               std::string("kernel version 999")}}) {
    const std::string plugin_name = plugin;  // clang 14 cannot capture a structured binding
    CAPTURE(plugin_name);
    json job = blowup_job(json::array({state(0.5, 0.25), state(0.7, 0.1)}), json::object(), plugin);
    const auto file = write_job(folder / "job.json", job);
    const auto run = run_with("baseline", folder, "out-" + std::to_string(note.size()), file);
    CHECK(run.status == 0);
    CHECK(run.summary["stepping"]["path"] == "evaluation");
    CHECK(run.summary["stepping"]["note"].get<std::string>().find(note) != std::string::npos);
  }
}

TEST_CASE("kernel path: Gauss-Legendre through the plugin's gauss_steps gives the evaluation path's files") {
  TemporaryFolder folder;
  // paper1d in both forms, 1, 5 and 300 states (blocks of 32 and a rest), 1 and 2 threads; with 3 stages also a
  // Lyapunov vector (the tangent map linearises at the kernel's stage points) and a state whose iteration fails at
  // its first step (the kernel's step is taken again through the evaluations, which retire that state alone).
  for (const int stages : {1, 3, 8})
    for (const char* form : {"TTV", "VVT"})
      for (std::size_t count : {std::size_t{1}, std::size_t{5}, std::size_t{300}}) {
        CAPTURE(stages);
        CAPTURE(form);
        CAPTURE(count);
        json initial = states(count);
        if (stages == 3 && count == 5) initial.push_back(state(3.0, 3.0));
        json job = paper1d_job(initial, {{"dt", 0.05}, {"steps", 40}}, {{"scheme", "gauss"}, {"stages", stages}});
        job["hamiltonian"] = form;
        job["output"] = {{"every", 10}};
        if (stages == 3) job["analysis"] = {{"lyapunov", {{"vectors", 1}}}};
        const auto file = write_job(folder / "job.json", job);
        const char* threads = count == 300 ? "2" : "1";
        check_same_files(run_with("baseline", folder, "kernel", file, threads),
                         run_with("evaluation", folder, "evaluation", file, threads));
      }
  // A model given by H (no Chin kernels, a Gauss-Legendre kernel).
  json henon = json::array();
  for (int i = 0; i < 40; ++i) henon.push_back({{"q", {0.02 * i - 0.4, 0.1}}, {"p", {0.1, 0.01 * i - 0.2}}});
  json job = {{"model", {{"plugin", "henon_heiles"}}},
              {"integrator", {{"scheme", "gauss"}, {"stages", 4}}},
              {"initial", henon},
              {"time", {{"dt", 0.1}, {"steps", 100}}},
              {"output", {{"every", 25}}}};
  const auto file = write_job(folder / "henon.json", job);
  check_same_files(run_with("baseline", folder, "kernel", file), run_with("evaluation", folder, "evaluation", file));
  // paper2d and paper1d write out every derivative grad H needs: their kernels are flattened and have wider copies
  // (x86-64-v3, v4, without fused multiply-adds), which the plugin runs where the processor runs them, whatever
  // NONSEP_INSTRUCTION_SET pins for the Chin kernels; paper2d's two degrees of freedom interleave in those vectors.
  json orbits = json::array();
  for (int i = 0; i < 70; ++i) orbits.push_back({{"q", {0.0, 0.01 * i}}, {"p", {0.5 + 0.002 * i, 2.0}}});
  for (const int stages : {2, 3, 8}) {
    CAPTURE(stages);
    const json paper2d = {{"model", {{"plugin", "paper2d"}}},
                          {"integrator", {{"scheme", "gauss"}, {"stages", stages}}},
                          {"initial", orbits},
                          {"time", {{"dt", 0.02}, {"steps", 50}}},
                          {"output", {{"every", 25}}}};
    const auto orbits_file = write_job(folder / "paper2d.json", paper2d);
    check_same_files(run_with("baseline", folder, "kernel", orbits_file),
                     run_with("evaluation", folder, "evaluation", orbits_file));
    // The same model with the x86-64-v3 copy as its wider one (tests/host/plugins/gauss_v3.cpp).
    json v3 = paper2d;
    v3["model"]["plugin"] = "gauss_v3";
    const auto v3_file = write_job(folder / "gauss_v3.json", v3);
    check_same_files(run_with("baseline", folder, "kernel", v3_file),
                     run_with("evaluation", folder, "evaluation", v3_file));
  }
}

TEST_CASE("inspect shows a plugin's kernels and --check compares them with the evaluation path") {
  TemporaryFolder folder;
  const auto shown = run_nonsep({"inspect", "paper1d"}, folder.path());
  CHECK(shown.status == 0);
  CHECK(shown.out.find("kernels:     version " + std::to_string(nonsep::chin_kernel_version) + " for x86-64") !=
        std::string::npos);
  CHECK(shown.out.find("runs use x86-64 (pinned by NONSEP_INSTRUCTION_SET)") != std::string::npos);
  const auto checked = run_nonsep({"inspect", "paper1d", "--check"}, folder.path());
  INFO(checked.out);
  CHECK(checked.status == 0);
  CHECK(checked.out.find("kernel x86-64: identical to the evaluation path bit for bit [used by runs]") !=
        std::string::npos);
  CHECK(checked.out.find("tangent kernel x86-64 (basic, 2 vectors): identical to the evaluation path bit for bit") !=
        std::string::npos);
  CHECK(checked.out.find("Gauss-Legendre kernel (8 steps of gauss 3 stages, dt 0.001, TTV and VVT, ") !=
        std::string::npos);
  CHECK(checked.out.find("states): identical to the evaluation path bit for bit") != std::string::npos);
  const auto general = run_nonsep({"inspect", "henon_heiles", "--check"}, folder.path());
  INFO(general.out);
  CHECK(general.status == 0);
  CHECK(general.out.find("Gauss-Legendre kernel (8 steps of gauss 3 stages, dt 0.001, ") != std::string::npos);
  CHECK(general.out.find("states): identical to the evaluation path bit for bit") != std::string::npos);
  const auto none = run_nonsep({"inspect", "blowup", "--check"}, folder.path());
  CHECK(none.out.find("kernels: none (the evaluation path steps this plugin)") != std::string::npos);
}

TEST_CASE("NONSEP_INSTRUCTION_SET naming a set the plugin lacks is refused with the sets it has") {
  TemporaryFolder folder;
  InstructionSet pin("x86-64-v9");
  const auto result = run_nonsep({"inspect", "paper1d"}, folder.path());
  CHECK(result.status == 2);
  CHECK(result.err.find("NONSEP_INSTRUCTION_SET=x86-64-v9 names no kernel of this plugin (it has x86-64") !=
        std::string::npos);
}

TEST_CASE(
    "a plugin with the default kernels carries this machine's widest set alone, and the baseline pinned is refused") {
  TemporaryFolder folder;
  std::string sets;
  {
    InstructionSet pin("evaluation");
    const auto shown = run_nonsep({"inspect", "native_kernels"}, folder.path());
    REQUIRE(shown.status == 0);
    const std::string prefix = "kernels:     version " + std::to_string(nonsep::chin_kernel_version) + " for ";
    const auto at = shown.out.find(prefix);
    REQUIRE(at != std::string::npos);
    const auto from = at + prefix.size();
    sets = shown.out.substr(from, shown.out.find(';', from) - from);
  }
  INFO("kernels: " << sets);
  const auto pinned = run_nonsep({"inspect", "native_kernels"}, folder.path());
  if (sets == "x86-64") {
    // This processor runs no wider set: the baseline is the native one, and runs.
    CHECK(pinned.status == 0);
  } else {
    CHECK((sets == "x86-64-v4" || sets == "x86-64-v3"));
    CHECK(pinned.status == 2);
    CHECK(pinned.err.find("NONSEP_INSTRUCTION_SET=x86-64 names no kernel of this plugin (it has " + sets +
                          "); the evaluation path, NONSEP_INSTRUCTION_SET=evaluation, gives the baseline kernel's "
                          "numbers bit for bit") != std::string::npos);
    CHECK(pinned.err.find("KERNEL_SETS native+baseline") != std::string::npos);
  }
}

}  // namespace test_host_kernels
