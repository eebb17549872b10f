#pragma once
// Helpers for the host's tests: temporary folders, writing job files, and running the built `nonsep` executable
// (NONSEP_EXECUTABLE, a compile definition) with its stdout and stderr captured.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace nonsep::host_testing {

// A fresh folder under the system's temporary folder, removed with its contents on destruction.
class TemporaryFolder {
 public:
  TemporaryFolder() {
    std::string pattern = (std::filesystem::temp_directory_path() / "nonsep-host-test-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TemporaryFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TemporaryFolder(const TemporaryFolder&) = delete;
  TemporaryFolder& operator=(const TemporaryFolder&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

inline nlohmann::json read_json(const std::filesystem::path& path) { return nlohmann::json::parse(read_text(path)); }

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

inline std::filesystem::path write_job(const std::filesystem::path& path, const nlohmann::json& job) {
  write_text(path, job.dump(2));
  return path;
}

// The quickstart job of examples/jobs/quickstart.json, as a JSON value to modify.
inline nlohmann::json quickstart_job() {
  return read_json(std::filesystem::path(NONSEP_SOURCE_DIR) / "examples/jobs/quickstart.json");
}

// Makes the test plugins (tests/host/plugins) findable by name.
inline void use_test_plugins() { ::setenv("NONSEP_PLUGIN_PATH", NONSEP_TEST_PLUGIN_DIR, 1); }

struct Process {
  pid_t pid = -1;
  std::filesystem::path out, err;
};

// Starts the program argv[0] (a path) with arguments argv[1...], stdout and stderr going to files in `folder`, with
// the signals `default_signals` at their default disposition whatever this process's is.
inline Process start_process(std::vector<std::string> argv_storage, const std::filesystem::path& folder,
                             const std::vector<int>& default_signals = {}) {
  use_test_plugins();
  static int serial = 0;
  Process process;
  process.out = folder / ("stdout-" + std::to_string(++serial) + ".txt");
  process.err = folder / ("stderr-" + std::to_string(serial) + ".txt");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, process.out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, process.err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::vector<char*> argv;
  for (auto& arg : argv_storage) argv.push_back(arg.data());
  argv.push_back(nullptr);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t defaults;
  sigemptyset(&defaults);
  for (int signal : default_signals) sigaddset(&defaults, signal);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGDEF);
  const int error = posix_spawn(&process.pid, argv[0], &actions, &attributes, argv.data(), environ);
  posix_spawnattr_destroy(&attributes);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) throw std::runtime_error("cannot start " + argv_storage[0]);
  return process;
}

// Starts `nonsep args...` with stdout and stderr going to files in `folder`.
inline Process start_nonsep(const std::vector<std::string>& args, const std::filesystem::path& folder) {
  std::vector<std::string> argv{NONSEP_EXECUTABLE};
  argv.insert(argv.end(), args.begin(), args.end());
  return start_process(std::move(argv), folder);
}

struct Result {
  int status = -1;      // the exit status, or 128 + signal number when killed by a signal
  bool killed = false;  // ended by a signal rather than by exiting (status 143 alone does not tell)
  std::string out, err;
};

// Waits for `process` to end; after `timeout` it is killed (SIGKILL) and std::runtime_error thrown, so that a test
// of a process that fails to stop fails instead of hanging. The default bounds a whole run under the sanitizers.
inline Result finish(const Process& process, std::chrono::seconds timeout = std::chrono::seconds(900)) {
  int wait_status = 0;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const pid_t done = ::waitpid(process.pid, &wait_status, WNOHANG);
    if (done == process.pid) break;
    if (done < 0) throw std::runtime_error("waitpid failed");
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(process.pid, SIGKILL);
      ::waitpid(process.pid, &wait_status, 0);
      throw std::runtime_error("nonsep did not finish within " + std::to_string(timeout.count()) + " s; killed");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  Result result;
  result.status = WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : 128 + WTERMSIG(wait_status);
  result.killed = WIFSIGNALED(wait_status);
  result.out = read_text(process.out);
  result.err = read_text(process.err);
  return result;
}

// Polls `condition` (a callable returning bool) every few milliseconds until it holds: true as soon as it does,
// false once `timeout` has passed without it. Tests wait on what they need (a file, a row count), never a fixed time.
// The default timeout is generous because it only bounds a failure: under the sanitizers a run reaches its
// checkpoints and units ten to fifty times later than in the release build.
template <class Condition>
bool wait_until(Condition condition, std::chrono::seconds timeout = std::chrono::seconds(300)) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

// Runs `nonsep args...` to completion.
inline Result run_nonsep(const std::vector<std::string>& args, const std::filesystem::path& folder) {
  return finish(start_nonsep(args, folder));
}

// Runs `nonsep run --quiet --output FOLDER/NAME [EXTRA...] FOLDER/NAME.json` with `job` written there, to completion;
// the process result (no status check).
inline Result run_named(const TemporaryFolder& folder, const std::string& name, const nlohmann::json& job,
                        const std::vector<std::string>& extra = {}) {
  const auto file = write_job(folder / (name + ".json"), job);
  std::vector<std::string> args{"run", "--quiet", "--output", (folder / name).string()};
  args.insert(args.end(), extra.begin(), extra.end());
  args.push_back(file.string());
  return run_nonsep(args, folder.path());
}

// Starts `nonsep run --quiet --output OUTPUT JOB_FILE`, waits until its checkpoint.json is at step `at_least` or
// later, kills the process with SIGKILL and returns the step of the checkpoint it left (a test then resumes it).
// Throws (failing the test) when no such checkpoint appears within wait_until's timeout.
inline std::uint64_t kill_after_checkpoint(const std::filesystem::path& job_file, const std::filesystem::path& output,
                                           std::uint64_t at_least, const std::filesystem::path& folder) {
  const auto process = start_nonsep({"run", "--quiet", "--output", output.string(), job_file.string()}, folder);
  const auto checkpoint_step = [&] { return read_json(output / "checkpoint.json")["step"].get<std::uint64_t>(); };
  const bool reached = wait_until([&] {
    try {
      return checkpoint_step() >= at_least;
    } catch (const std::exception&) {
      return false;
    }
  });
  ::kill(process.pid, SIGKILL);
  finish(process, std::chrono::seconds(30));
  if (!reached)
    throw std::runtime_error("no checkpoint at step " + std::to_string(at_least) + " or later in 300 s in " +
                             output.string());
  return checkpoint_step();
}

// The rows of CSV text, split at commas (no quoting in nonsep's files); row 0 is the header.
inline std::vector<std::vector<std::string>> parse_csv(const std::string& csv) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream text(csv);
  std::string line;
  while (std::getline(text, line)) {
    std::vector<std::string> cells;
    std::string cell;
    std::istringstream fields(line);
    while (std::getline(fields, cell, ',')) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.push_back("");
    rows.push_back(cells);
  }
  return rows;
}

// The rows of a CSV file, as parse_csv.
inline std::vector<std::vector<std::string>> read_csv(const std::filesystem::path& path) {
  return parse_csv(read_text(path));
}

// The rows of a CSV file (a run's trajectories.csv, ...) as one map of named cells per row; an empty file throws.
inline std::vector<std::map<std::string, std::string>> table(const std::filesystem::path& path) {
  const auto rows = read_csv(path);
  if (rows.empty()) throw std::runtime_error(path.string() + " has no header");
  std::vector<std::map<std::string, std::string>> result;
  for (std::size_t r = 1; r < rows.size(); ++r) {
    std::map<std::string, std::string> row;
    for (std::size_t c = 0; c < rows[0].size(); ++c) row[rows[0][c]] = c < rows[r].size() ? rows[r][c] : "";
    result.push_back(std::move(row));
  }
  return result;
}

// The number in the cell `name` of a row of table(); throws when the row has no such column.
inline double cell(const std::map<std::string, std::string>& row, const std::string& name) {
  const auto found = row.find(name);
  if (found == row.end()) throw std::runtime_error("no column " + name);
  return std::strtod(found->second.c_str(), nullptr);
}

// A run's results as one JSON value: summary.json with "trajectories" set to one object per row of
// trajectories.csv: {index, status, final {t, step, q, p}, energy {initial, final, relative_error_final,
// relative_error_max_abs}, stop {step, t, variable} (when it stopped early), message (when there is one),
// closest_return {distance, t, step} or null (when the run tracked it)}. Empty cells are null; numbers are parsed
// exactly (the host writes shortest round-trip decimals).
inline nlohmann::json read_run(const std::filesystem::path& folder) {
  nlohmann::json summary = read_json(folder / "summary.json");
  const auto rows = read_csv(folder / "trajectories.csv");
  if (rows.empty()) throw std::runtime_error("trajectories.csv has no header");
  const auto& header = rows[0];
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t r = 1; r < rows.size(); ++r) {
    std::map<std::string, std::string> cell;
    for (std::size_t c = 0; c < header.size(); ++c) cell[header[c]] = c < rows[r].size() ? rows[r][c] : "";
    const auto number = [&](const std::string& name) -> nlohmann::json {
      const std::string& text = cell.at(name);
      if (text.empty()) return nullptr;
      return std::strtod(text.c_str(), nullptr);
    };
    const auto integer = [&](const std::string& name) -> nlohmann::json {
      const std::string& text = cell.at(name);
      if (text.empty()) return nullptr;
      return std::stoull(text);
    };
    nlohmann::json q = nlohmann::json::array(), p = nlohmann::json::array();
    for (std::size_t i = 0; cell.count("q" + std::to_string(i)); ++i) {
      if (cell.at("q" + std::to_string(i)).empty()) continue;
      q.push_back(number("q" + std::to_string(i)));
      p.push_back(number("p" + std::to_string(i)));
    }
    nlohmann::json entry = {{"index", std::stoull(cell.at("trajectory"))},
                            {"status", cell.at("status")},
                            {"final", {{"t", number("t")}, {"step", integer("step")}, {"q", q}, {"p", p}}},
                            {"energy",
                             {{"initial", number("H0")},
                              {"final", number("H")},
                              {"relative_error_final", number("relative_energy_error")},
                              {"relative_error_max_abs", number("max_abs_relative_energy_error")}}}};
    if (!cell.at("stop_step").empty())
      entry["stop"] = {{"step", integer("stop_step")}, {"t", number("stop_t")}, {"variable", cell.at("stop_variable")}};
    if (!cell.at("message").empty()) entry["message"] = cell.at("message");
    if (cell.count("closest_return_distance"))
      entry["closest_return"] = cell.at("closest_return_distance").empty()
                                    ? nlohmann::json(nullptr)
                                    : nlohmann::json{{"distance", number("closest_return_distance")},
                                                     {"t", number("closest_return_t")},
                                                     {"step", integer("closest_return_step")}};
    list.push_back(std::move(entry));
  }
  summary["trajectories"] = std::move(list);
  return summary;
}

}  // namespace nonsep::host_testing
