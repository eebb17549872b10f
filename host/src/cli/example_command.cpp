// `nonsep example [NAME] [--output FILE] [--list]`: a starting job file. The examples are the job files of
// share/nonsep/examples/{jobs,paper,dynamics} beside the executable (platform/installation.hpp); the quickstart job is
// also compiled in (examples/jobs/quickstart.json, embedded_examples.cpp), so it is there even when the executable was
// copied alone. The written file is the example's text unchanged but for "$schema", which is made to point at the
// schema of this installation (the examples' own value is relative to their folder).
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>

#include "cli/commands.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/platform/installation.hpp"

namespace nonsep::host::cli {

namespace fs = std::filesystem;

namespace {

constexpr const char* default_example = "quickstart";

// Name -> file, over share/nonsep/examples/jobs, examples/paper, then examples/dynamics (the first of a name wins).
std::map<std::string, fs::path> installed_examples() {
  std::map<std::string, fs::path> examples;
  const auto data = data_directory();
  if (!data) return examples;
  for (const char* folder : {"jobs", "paper", "dynamics"}) {
    std::error_code error;
    for (fs::directory_iterator entry(*data / "examples" / folder, error), end; !error && entry != end;
         entry.increment(error))
      if (entry->path().extension() == ".json" && entry->is_regular_file())
        examples.emplace(entry->path().stem().string(), entry->path());
  }
  return examples;
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) throw std::runtime_error("cannot read " + path.string());
  return text.str();
}

// The first sentence of the example's "description" (up to ". " and a capital letter, so not "eq. 12"), or "".
std::string short_description(const fs::path& file) {
  try {
    const auto job = nlohmann::json::parse(read_file(file));
    const std::string text = job.value("description", "");
    for (std::size_t end = text.find(". "); end != std::string::npos; end = text.find(". ", end + 1))
      if (end + 2 < text.size() && std::isupper(static_cast<unsigned char>(text[end + 2])))
        return text.substr(0, end + 1);
    return text;
  } catch (const std::exception&) {
    return "";
  }
}

std::string names_text(const std::map<std::string, fs::path>& examples) {
  std::string names = default_example;
  for (const auto& [name, file] : examples)
    if (name != default_example) names += ", " + name;
  return names;
}

// "$schema": "<relative to the example's folder>" -> the absolute path of this installation's schema; left as it
// is when the schema is not found beside the executable (nonsep ignores "$schema"; only editors read it).
std::string with_installed_schema(std::string text) {
  static const std::regex member(R"re("\$schema"\s*:\s*"[^"\n]*")re");
  std::smatch found;
  const auto data = data_directory();
  if (!data || !std::regex_search(text, found, member)) return text;
  std::error_code error;
  const fs::path schema = fs::canonical(*data / "schemas" / "job.schema.json", error);
  if (error) return text;
  text.replace(static_cast<std::size_t>(found.position(0)), static_cast<std::size_t>(found.length(0)),
               "\"$schema\": " + nlohmann::json(schema.string()).dump());
  return text;
}

// "directory": "<example>.out" -> "<stem of FILE>.out": the examples name their folder as the default would for
// their own file name, so without this `nonsep example --output orbit.json && nonsep run orbit.json` wrote to
// quickstart.out, not orbit.out as docs/user-guide.md says of the default, and two copies of one example shared a
// folder.
std::string with_output_folder_of(std::string text, const std::string& example, const fs::path& file) {
  const std::string stem = file.stem().string();
  if (stem.empty() || stem == example) return text;
  static const std::regex unsafe(R"re([^A-Za-z0-9_-])re");
  if (std::regex_search(example, unsafe)) return text;
  const std::regex member("\"directory\"\\s*:\\s*\"" + example + "\\.out\"");
  std::string replacement = "\"directory\": " + nlohmann::json(stem + ".out").dump();
  for (std::size_t at = 0; (at = replacement.find('$', at)) != std::string::npos; at += 2)
    replacement.insert(at, "$");  // "$$": a literal $ in a regex_replace format
  return std::regex_replace(text, member, replacement, std::regex_constants::format_first_only);
}

}  // namespace

int command_example(const ExampleArguments& arguments) {
  const auto examples = installed_examples();
  if (arguments.list) {
    std::size_t width = std::string(default_example).size();
    for (const auto& [name, file] : examples) width = std::max(width, name.size());
    const auto row = [&](const std::string& name, const std::string& description) {
      std::cout << "  " << name << std::string(width - name.size() + 2, ' ') << description << "\n";
    };
    row(default_example, examples.count(default_example) ? short_description(examples.at(default_example))
                                                         : std::string("(compiled in)"));
    for (const auto& [name, file] : examples)
      if (name != default_example) row(name, short_description(file));
    if (examples.empty())
      std::cerr << "nonsep: only the compiled-in quickstart: no example folder beside this executable ("
                << manual_location() << ")\n";
    return to_int(ExitStatus::success);
  }
  const std::string name = arguments.name.empty() ? default_example : arguments.name;
  std::string text;
  if (const auto found = examples.find(name); found != examples.end()) {
    text = read_file(found->second);
  } else if (name == default_example) {
    text = embedded_quickstart_job();
  } else {
    std::cerr << "nonsep: no example named '" << name << "'; the examples are " << names_text(examples)
              << (examples.empty() ? " (no example folder was found beside this executable)" : "")
              << "; `nonsep example --list` describes them\n";
    return to_int(ExitStatus::invalid_input);
  }
  text = with_installed_schema(text);

  if (arguments.output.empty()) {
    std::cout << text;
    if (arguments.name.empty())
      std::cerr << "nonsep: wrote the " << default_example << " job; the examples are " << names_text(examples)
                << " (`nonsep example NAME --output FILE`, `nonsep example --list`)\n";
    return to_int(ExitStatus::success);
  }
  const fs::path file = arguments.output;
  text = with_output_folder_of(text, name, file);
  // O_EXCL: created here or not at all, never an existing file and never through a symbolic link.
  const int descriptor = ::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (descriptor < 0 && errno == EEXIST) {
    std::cerr << "nonsep: " << file.string()
              << " already exists; `nonsep example` does not overwrite files: choose another name or remove it\n";
    return to_int(ExitStatus::invalid_input);
  }
  std::size_t written = 0;
  if (descriptor >= 0) {
    while (written < text.size()) {
      const ssize_t n = ::write(descriptor, text.data() + written, text.size() - written);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      written += static_cast<std::size_t>(n);
    }
    if (::close(descriptor) != 0) written = 0;
  }
  if (descriptor < 0 || written < text.size()) {
    const std::string reason = std::strerror(errno);
    if (descriptor >= 0) ::unlink(file.c_str());
    std::cerr << "nonsep: cannot write the example job to " << file.string() << " (" << reason << ")\n";
    return to_int(ExitStatus::invalid_input);
  }
  std::cout << "wrote the example '" << name << "' to " << file.string() << "; check it with `nonsep validate "
            << file.string() << "`, run it with `nonsep run " << file.string() << "`\n";
  if (arguments.name.empty())
    std::cout << "the examples are " << names_text(examples) << " (`nonsep example --list` describes them)\n";
  return to_int(ExitStatus::success);
}

}  // namespace nonsep::host::cli
