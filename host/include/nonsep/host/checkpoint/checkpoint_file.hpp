#pragma once
// checkpoint.json: everything a run needs to continue, bit for bit, after an interruption or a crash
// (`nonsep run JOB --resume`). This file identifies the job (checkpoint_identity: computed once per run, before its
// driver is built, launch/run_plan.hpp) and reads the file (load_checkpoint, once, before a resumed run's driver
// starts); CheckpointSaver (checkpoint_saver.hpp) owns the file's format and writes it.
//
// A checkpoint is taken between two steps and holds: the number of steps completed, the active states in
// trajectory order with their energies, every trajectory's record (retired ones included: status, final state,
// energies), the evaluation counts, every observer's state (observer.hpp: trajectory.csv's size, which a resumed
// run cuts the file back to, the largest energy errors, the closest returns, ...), and a fingerprint of the job.
// Doubles are stored as shortest round-trip decimal strings
// ("0.1", "nan", "-inf"), so reading one back gives the same bits. The file is replaced atomically
// (write_file_atomically): a crash while saving leaves the previous checkpoint.
//
// It also records how the steps were computed (stepping_identity below): the instruction set of the plugin's stepping
// kernel, or the evaluation path. A resume that would step another way is refused (check_stepping): the wider sets
// fuse multiplications and additions, so its numbers would be those of neither uninterrupted run.
//
// The fingerprint covers what determines the numbers: the plugin (name, version and its file's bytes), the model's
// parameters, the integrator (its scheme, form and every option of its catalogue entry; with scheme "auto" the chosen
// one, and the tolerance and measure asked for), the initial states, the time grid, output.every,
// output.energy_every, output.format (hdf5 only) and /analysis (error_estimate included: its state is in the
// checkpoint). A run of scheme "auto" also records the choice its pilots made, which its resume reuses. It leaves out
// the output folder and the checkpoint policy, which may change between the interrupted run and the resumed one.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "nonsep/core/base/model.hpp"
#include "nonsep/host/checkpoint/checkpoint_saver.hpp"  // the format, checkpoint_file_name, CheckpointIdentity
#include "nonsep/host/job.hpp"
#include "nonsep/host/run/ensemble_driver.hpp"
#include "nonsep/host/run/saved_state.hpp"  // CheckpointError

namespace nonsep::host {

// What a checkpoint holds: the driver's state and each observer's, by its name().
struct Checkpoint {
  DriverState driver;
  nlohmann::json observers = nlohmann::json::object();
};

// What identifies the job's numbers, as described above, in named parts, each 16 hexadecimal digits (FNV-1a, 64
// bits): "plugin:... parameters:... integrator:... integrator.order:... ... initial:... time:... output:...
// analysis:...", one integrator.NAME part per option of the scheme's catalogue entry. The plugin part covers the
// plugin's name, version and the bytes of its file.
std::string job_fingerprint(const LoadedJob& job);
// The names of the parts in which two fingerprints differ ("plugin, integrator.omega, time").
std::string fingerprint_difference(const std::string& a, const std::string& b);
// The same as a sentence's end: "time differs", "plugin, integrator.omega, time differ".
std::string what_differs(const std::string& a, const std::string& b);

// How this process steps `job`'s plugin, which decides the last bits of the numbers: the instruction set of the
// plugin's kernel it uses ("x86-64-v4", Plugin::kernels()), or "evaluation" for the evaluation path (the plugin has
// no kernel of this nonsep's version, this processor runs none, or NONSEP_INSTRUCTION_SET=evaluation). Fixed when the
// plugin is loaded, whether or not the job's steps reach the kernel (every-step observers and tangent vectors step
// through the evaluation path).
std::string stepping_identity(const LoadedJob& job);
// Throws CheckpointError when `recorded`, the stepping_identity that `written` (a checkpoint, a distributed run's
// plan) was written with, differs from this process's: the message names both and NONSEP_INSTRUCTION_SET, which
// chooses the stepping.
void check_stepping(const std::string& recorded, const LoadedJob& job, const std::filesystem::path& written);

// The job's identity as a checkpoint records it: job_fingerprint and stepping_identity, and with scheme "auto" the
// choice its pilots made (`scheme_choice`, null without "auto").
CheckpointIdentity checkpoint_identity(const LoadedJob& job, const nlohmann::ordered_json& scheme_choice = nullptr);

// Scheme "auto": the choice recorded in the checkpoint at `path` (CheckpointIdentity::scheme_choice), which a resumed
// run applies (study/scheme_choice.hpp apply_recorded_choice) before its identity, which covers the chosen integrator,
// can be known; load_checkpoint then checks the rest. Throws CheckpointError: the file is missing or damaged, or was
// written by a run without "auto".
nlohmann::ordered_json recorded_scheme_choice(const std::filesystem::path& path);

// Reads the checkpoint at `path` and checks it against the job, whose identity is `identity` (fingerprint,
// stepping), and against its number of trajectories, dimension and steps. The observers' states are checked by the
// observers' restore(). Throws CheckpointError.
Checkpoint load_checkpoint(const std::filesystem::path& path, const LoadedJob& job, const CheckpointIdentity& identity);
// The same with checkpoint_identity(job).
Checkpoint load_checkpoint(const std::filesystem::path& path, const LoadedJob& job);

}  // namespace nonsep::host
