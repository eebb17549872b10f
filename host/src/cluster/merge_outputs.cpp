#include "nonsep/host/cluster/merge_outputs.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <memory>
#include <optional>
#include <queue>
#include <tuple>

#include "nonsep/host/launch/run_job.hpp"
#include "nonsep/host/observers/sampled_indicator.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/csv_reader.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"
#include "nonsep/host/run/trajectory.hpp"

namespace nonsep::host {

namespace {

struct Part {
  const UnitFile* file;
  std::optional<CsvReader> rows;
  std::vector<std::string> cells;  // of the row last read (rows->text() as it is in the file)
  std::vector<std::uint64_t> key;
  std::uint64_t line = 1;
};

[[noreturn]] void unfit(const Part& part, const std::string& what) {
  throw OutputError(part.file->path.string() + " line " + std::to_string(part.line) + ": " + what +
                    " (a unit's file of a distributed run cannot be merged)");
}

}  // namespace

void merge_csv(std::span<const UnitFile> parts, const std::filesystem::path& output,
               std::span<const std::string> keys) {
  std::vector<std::unique_ptr<Part>> open;
  std::string header;
  std::vector<std::size_t> key_columns;
  std::size_t trajectory_column = 0, leading = 0;
  for (const UnitFile& file : parts) {
    auto part = std::make_unique<Part>();
    part->file = &file;
    try {
      part->rows.emplace(file.path, "to merge it");
    } catch (const OutputError&) {
      unfit(*part, "missing or empty");
    }
    if (!part->rows->next(part->cells)) unfit(*part, "missing or empty");
    const std::string& first = part->rows->text();
    if (open.empty()) {
      header = first;
      const std::vector<std::string>& names = part->cells;
      const auto column = [&](const std::string& name) {
        const auto at = std::find(names.begin(), names.end(), name);
        if (at == names.end()) unfit(*part, "no column " + name);
        return static_cast<std::size_t>(at - names.begin());
      };
      for (const std::string& key : keys) key_columns.push_back(column(key));
      trajectory_column = column("trajectory");
      leading = std::max(trajectory_column, *std::max_element(key_columns.begin(), key_columns.end())) + 1;
    } else if (first != header) {
      unfit(*part, "its header differs from " + parts.front().path.string() + "'s");
    }
    open.push_back(std::move(part));
  }
  const auto advance = [&](Part& part) {
    if (!part.rows->next(part.cells)) return false;
    ++part.line;
    if (part.cells.size() < leading) unfit(part, "too few cells");
    part.key.clear();
    for (std::size_t column : key_columns) {
      std::uint64_t value = 0;
      const std::string& cell = part.cells[column];
      auto [end, error] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
      if (error != std::errc() || end != cell.data() + cell.size()) unfit(part, "not an integer key");
      if (column == trajectory_column) value += part.file->first_trajectory;
      part.key.push_back(value);
    }
    return true;
  };
  const auto later = [](const Part* a, const Part* b) { return std::tie(a->key, a->file) > std::tie(b->key, b->file); };
  std::priority_queue<Part*, std::vector<Part*>, decltype(later)> queue(later);
  for (auto& part : open)
    if (advance(*part)) queue.push(part.get());

  AtomicFile file(output);
  std::string text = header + "\n";
  while (!queue.empty()) {
    Part* part = queue.top();
    queue.pop();
    // The row with its trajectory number shifted: the cells before it, the new number, the rest.
    const std::string& record = part->rows->text();
    const std::string& cell = part->cells[trajectory_column];
    const std::size_t begin = part->rows->offset(trajectory_column);
    text.append(record, 0, begin);
    std::uint64_t local = 0;
    std::from_chars(cell.data(), cell.data() + cell.size(), local);
    text += std::to_string(local + part->file->first_trajectory);
    text.append(record, begin + cell.size());
    text += '\n';
    if (text.size() >= (1 << 20)) {
      file.write(text);
      text.clear();
    }
    if (advance(*part)) queue.push(part);
  }
  file.write(text);
  file.commit();
}

void merge_signals(std::span<const UnitFile> parts, const std::filesystem::path& output) {
  struct Unit {
    int descriptor;
    std::uint64_t offset, bytes;
  };
  std::vector<Unit> units;
  const auto close_all = [&] {
    for (const Unit& unit : units) ::close(unit.descriptor);
  };
  std::uint64_t trajectories = 0;
  std::optional<std::array<std::uint64_t, 3>> first;
  try {
    for (const UnitFile& file : parts) {
      const auto refuse = [&](const std::string& what) {
        throw OutputError(file.path.string() + ": " + what + " (a unit's file of a distributed run cannot be merged)");
      };
      const int descriptor = open_regular_file(file.path);
      if (descriptor < 0) refuse("missing");
      units.push_back({descriptor, 0, 0});
      std::string header(10, '\0');
      if (::pread(descriptor, header.data(), 10, 0) != 10) refuse("not a NumPy file");
      header.resize(10 + static_cast<unsigned char>(header[8]) + 256u * static_cast<unsigned char>(header[9]));
      const auto length = static_cast<ssize_t>(header.size() - 10);
      if (::pread(descriptor, header.data() + 10, header.size() - 10, 10) != length) refuse("a short header");
      const auto shape = SampledIndicatorObserver::signals_shape(header);
      if (!shape) refuse("not an array of frequency map signals");
      if (first && ((*first)[1] != (*shape)[1] || (*first)[2] != (*shape)[2]))
        refuse("signals or samples other than the first unit's");
      if (!first) first = shape;
      units.back().offset = header.size();
      units.back().bytes = (*shape)[0] * (*shape)[1] * (*shape)[2] * sizeof(double) * 2;
      trajectories += (*shape)[0];
    }
    if (!first) throw OutputError(output.string() + ": no unit to merge");
    AtomicFile merged(output);
    merged.write(SampledIndicatorObserver::signals_header(trajectories, (*first)[1], (*first)[2]));
    std::string buffer(std::size_t{1} << 20, '\0');
    for (std::size_t u = 0; u < units.size(); ++u)
      for (std::uint64_t done = 0; done < units[u].bytes;) {
        const std::uint64_t size = std::min<std::uint64_t>(buffer.size(), units[u].bytes - done);
        const ssize_t n = ::pread(units[u].descriptor, buffer.data(), size, static_cast<off_t>(units[u].offset + done));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0)
          throw OutputError(parts[u].path.string() +
                            ": shorter than its header says (a unit's file of a distributed "
                            "run cannot be merged)");
        merged.write(std::string_view(buffer.data(), static_cast<std::size_t>(n)));
        done += static_cast<std::uint64_t>(n);
      }
    merged.commit();
  } catch (...) {
    close_all();
    throw;
  }
  close_all();
}

namespace {

using nlohmann::ordered_json;

// What a unit's status says of how its driver ended; its counts say the rest (run_status).
DriverEnd driver_end(const ordered_json& summary) {
  const auto status = trajectory_status_from_string(summary.value("status", "failed"));
  if (status == TrajectoryStatus::interrupted) return DriverEnd::interrupted;
  if (!status || status == TrajectoryStatus::failed) return DriverEnd::failed;
  return DriverEnd::completed;
}

// The counts of summary.json's "counts" object.
StatusCounts status_counts(const ordered_json& counts) {
  StatusCounts result;
  for (const TrajectoryStatus status :
       {TrajectoryStatus::completed, TrajectoryStatus::diverged, TrajectoryStatus::failed, TrajectoryStatus::inaccurate,
        TrajectoryStatus::interrupted})
    result[status] = counts.value(std::string(to_string(status)), std::size_t{0});
  return result;
}

void add_counts(ordered_json& total, const ordered_json& part) {
  for (auto& [name, value] : total.items())
    if (part.contains(name) && value.is_number_integer())
      value = value.get<std::uint64_t>() + part[name].get<std::uint64_t>();
}

}  // namespace

ordered_json merge_summaries(std::span<const ordered_json> units, std::span<const std::size_t> first_trajectories,
                             std::size_t trajectories, const std::filesystem::path& directory, double wall_seconds) {
  ordered_json merged = units.front();
  DriverEnd end = driver_end(merged);
  std::string error = merged.value("error", "");
  for (std::size_t u = 1; u < units.size(); ++u) {
    const ordered_json& unit = units[u];
    if (const DriverEnd unit_end = driver_end(unit); unit_end != DriverEnd::completed && end != DriverEnd::interrupted)
      end = unit_end;
    if (const std::string e = unit.value("error", ""); !e.empty() && error.find(e) == std::string::npos)
      error += (error.empty() ? "" : "; ") + e;
    add_counts(merged["counts"], unit["counts"]);
    add_counts(merged["evaluations"], unit["evaluations"]);
    auto& completed = merged["time"]["steps_completed"];
    completed = std::max(completed.get<std::uint64_t>(), unit["time"]["steps_completed"].get<std::uint64_t>());
    // The scheme's figures (under its family's name, launch/run_summary.cpp) combine by the largest, as a process's
    // blocks do.
    if (const std::string family = merged.contains("integrator") ? merged["integrator"].value("family", "") : "";
        !family.empty() && merged.contains(family))
      for (auto figure = merged[family].begin(); figure != merged[family].end(); ++figure)
        if (figure->is_number()) *figure = std::max(figure->get<double>(), unit[family][figure.key()].get<double>());
    if (merged.contains("analysis") && merged["analysis"].contains("poincare"))
      merged["analysis"]["poincare"]["crossings"] = merged["analysis"]["poincare"]["crossings"].get<std::uint64_t>() +
                                                    unit["analysis"]["poincare"]["crossings"].get<std::uint64_t>();
    // The trajectories an indicator that needs samples analysed (launch/run_job.cpp: sampled_facts) add up.
    if (merged.contains("analysis"))
      for (auto entry = merged["analysis"].begin(); entry != merged["analysis"].end(); ++entry)
        if (entry->is_object() && entry->contains("analysed"))
          (*entry)["analysed"] = (*entry)["analysed"].get<std::uint64_t>() +
                                 unit["analysis"][entry.key()]["analysed"].get<std::uint64_t>();
  }
  // The largest energy error: strictly larger wins, as one process scans the trajectories in order.
  ordered_json largest = nullptr;
  for (std::size_t u = 0; u < units.size(); ++u) {
    const ordered_json& energy = units[u]["energy"];
    if (!energy.contains("largest_relative_error") || energy["largest_relative_error"].is_null()) continue;
    const ordered_json& candidate = energy["largest_relative_error"];
    if (largest.is_null() || candidate["value"].get<double>() > largest["value"].get<double>())
      largest = {{"value", candidate["value"]},
                 {"trajectory", candidate["trajectory"].get<std::uint64_t>() + first_trajectories[u]}};
  }
  if (merged["energy"].contains("largest_relative_error")) merged["energy"]["largest_relative_error"] = largest;
  merged["status"] = to_string(run_status(end, status_counts(merged["counts"])));
  if (!error.empty()) {
    // "error" follows "status", as run_summary writes it.
    ordered_json ordered;
    for (auto& [name, value] : merged.items()) {
      if (name == "error") continue;
      ordered[name] = value;
      if (name == "status") ordered["error"] = error;
    }
    merged = std::move(ordered);
  }
  merged["output"]["directory"] = directory.string();
  merged["trajectories"] = trajectories;
  if (merged.contains("energy_shell")) merged["energy_shell"]["states"] = trajectories;
  merged["wall_seconds"] = wall_seconds;
  return merged;
}

}  // namespace nonsep::host
