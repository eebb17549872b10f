#pragma once
// The seal of a finished work unit of a distributed run (nonsep/host/cluster/distributed_run.hpp):
// units/NNNNNN/.nonsep-unit.json, written by the rank that ran the unit once its files are complete. A unit counts
// as done only with its seal, and is merged only after verify_unit has checked it against the unit's files and the
// job being run: a unit cut short, edited, copied from another job or another unit, or overwritten by another run
// is refused (exit 2, naming the unit), never merged.
//
// The seal holds the unit's number, first trajectory and size, the fingerprint of the job restricted to the unit's
// trajectories (checkpoint/checkpoint_file.hpp's job_fingerprint: plugin, parameters, integrator and its options,
// initial states, time grid, outputs, analysis), and for each of the unit's files its size, content hash and number of
// rows (line ends). verify_unit also checks what the seal does not say: that trajectories.csv has one row per
// trajectory of the unit and summary.json names as many, and that no file has appeared or gone since.
#include <cstddef>
#include <filesystem>
#include <string>

namespace nonsep::host {

inline constexpr const char* unit_seal_name = ".nonsep-unit.json";

// Which unit of which job a unit folder must hold.
struct UnitIdentity {
  std::size_t unit = 0, first = 0, size = 0;
  std::string fingerprint;  // job_fingerprint of the job restricted to the unit
};

// Whether `folder` holds a seal (a regular file; it is not read).
bool has_seal(const std::filesystem::path& folder);

// Writes `folder`'s seal from its files as they are now. Throws OutputError.
void seal_unit(const std::filesystem::path& folder, const UnitIdentity& identity);

// Checks `folder` against its seal and `identity` as described above. Throws CheckpointError naming the unit's
// folder and what does not match.
void verify_unit(const std::filesystem::path& folder, const UnitIdentity& identity);

// Throws CheckpointError when `path` is anything but a folder (a symbolic link above all: a resume must not write
// the units' files outside the output folder) or, when `may_be_missing`, absent.
void check_real_folder(const std::filesystem::path& path, bool may_be_missing);

}  // namespace nonsep::host
