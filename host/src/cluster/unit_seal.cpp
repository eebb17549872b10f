#include "cluster/unit_seal.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string_view>

#include "nonsep/host/checkpoint/checkpoint_file.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/content_hash.hpp"
#include "nonsep/host/output/run_folder.hpp"

namespace nonsep::host {

namespace {

using nlohmann::ordered_json;
constexpr int seal_format = 1;

struct FileFacts {
  std::uint64_t bytes = 0, rows = 0, hash = content_hash_start;
};

// The facts of the regular file at `path`, read through one descriptor that follows no link and never blocks.
FileFacts facts_of(const std::filesystem::path& path) {
  const int descriptor = open_regular_file(path);
  if (descriptor < 0) throw OutputError("cannot read " + path.string() + ": it is gone");
  FileFacts facts;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t got = ::read(descriptor, buffer, sizeof buffer);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      const std::string reason = std::strerror(errno);
      ::close(descriptor);
      throw OutputError("cannot read " + path.string() + ": " + reason);
    }
    if (got == 0) break;
    const std::string_view piece(buffer, static_cast<std::size_t>(got));
    facts.bytes += piece.size();
    facts.hash = content_hash(piece, facts.hash);
    for (char c : piece) facts.rows += c == '\n';
  }
  ::close(descriptor);
  return facts;
}

// The unit's files, as RunFolder names a run's files, that are there now (its manifest and seal aside).
ordered_json files_of(const std::filesystem::path& folder) {
  ordered_json files = ordered_json::object();
  for (const std::string& name : RunFolder::output_files()) {
    std::error_code error;
    if (name.front() == '.' || !std::filesystem::exists(std::filesystem::symlink_status(folder / name, error)))
      continue;
    const FileFacts facts = facts_of(folder / name);
    files[name] = {{"bytes", facts.bytes}, {"rows", facts.rows}, {"hash", content_hash_hex(facts.hash)}};
  }
  return files;
}

}  // namespace

bool has_seal(const std::filesystem::path& folder) {
  std::error_code error;
  return std::filesystem::is_regular_file(std::filesystem::symlink_status(folder / unit_seal_name, error));
}

void seal_unit(const std::filesystem::path& folder, const UnitIdentity& identity) {
  const ordered_json seal = {{"format", seal_format},
                             {"unit", identity.unit},
                             {"first_trajectory", identity.first},
                             {"trajectories", identity.size},
                             {"job_fingerprint", identity.fingerprint},
                             {"files", files_of(folder)}};
  write_file_atomically(folder / unit_seal_name, seal.dump(2) + "\n");
}

void verify_unit(const std::filesystem::path& folder, const UnitIdentity& identity) {
  const auto refuse = [&](const std::string& what) {
    throw CheckpointError("work unit " + folder.string() + " (trajectories " + std::to_string(identity.first) + " to " +
                          std::to_string(identity.first + identity.size - 1) + ") " + what +
                          "; it is not merged. Run the job again with --force, or put back the unit's own files");
  };
  ordered_json seal, files, summary;
  try {
    seal = ordered_json::parse(read_regular_file(folder / unit_seal_name, 1 << 20).value_or(""));
    files = files_of(folder);
    summary = ordered_json::parse(read_regular_file(folder / "summary.json", 1 << 24).value_or(""));
  } catch (const std::exception& error) {
    refuse(std::string("cannot be read: ") + error.what());
  }
  try {
    if (seal.at("format") != seal_format || seal.at("unit") != identity.unit ||
        seal.at("first_trajectory") != identity.first || seal.at("trajectories") != identity.size)
      refuse("is sealed as another unit (" + folder.filename().string() + " holds " + seal.dump() + ")");
    if (const std::string sealed = seal.at("job_fingerprint").get<std::string>(); sealed != identity.fingerprint)
      refuse("was computed by another job: its " + what_differs(sealed, identity.fingerprint));
    for (const auto& [name, facts] : seal.at("files").items())
      if (!files.contains(name)) refuse("has lost its " + name);
    for (const auto& [name, facts] : files.items()) {
      if (!seal.at("files").contains(name)) refuse("has a " + name + " that was not among its files when it ended");
      const ordered_json& sealed = seal.at("files").at(name);
      if (sealed != facts)
        refuse("has a " + name + " that is not the one it ended with (" + facts["bytes"].dump() + " bytes, " +
               facts["rows"].dump() + " rows; sealed: " + sealed.at("bytes").dump() + " bytes, " +
               sealed.at("rows").dump() + " rows" + (sealed.at("bytes") == facts["bytes"] ? ", other content" : "") +
               ")");
    }
    if (!files.contains("trajectories.csv") || files["trajectories.csv"]["rows"] != identity.size + 1)
      refuse("does not have one row of trajectories.csv per trajectory");
    if (summary.at("trajectories") != identity.size || summary.at("status") == "interrupted")
      refuse("has a summary.json that is not of this unit's finished run");
  } catch (const nlohmann::ordered_json::exception& error) {
    refuse(std::string("has a damaged seal (") + unit_seal_name + "): " + error.what());
  }
}

void check_real_folder(const std::filesystem::path& path, bool may_be_missing) {
  std::error_code error;
  const auto status = std::filesystem::symlink_status(path, error);
  if (!std::filesystem::exists(status) && may_be_missing) return;
  if (std::filesystem::is_directory(status)) return;
  const std::string what = !std::filesystem::exists(status)      ? "missing"
                           : std::filesystem::is_symlink(status) ? "a symbolic link, not a folder"
                                                                 : "not a folder";
  throw CheckpointError(path.string() + " is " + what +
                        ": the work units of a distributed run are folders inside its output folder, and a resume "
                        "writes into nothing else; run the job again with --force");
}

}  // namespace nonsep::host
