#include <iostream>
#include <string>

#include "cli/commands.hpp"
#include "nonsep/host/exit_status.hpp"
#include "nonsep/host/number_format.hpp"

namespace nonsep::host::cli {

int command_validate(const std::string& job_file) {
  try {
    const LoadedJob loaded = load_job(job_file);
    const Job& job = loaded.job;
    if (job.is_study()) {
      const Study& study = job.study();
      std::cout << "valid: " << job_file << "\n"
                << "  model:       " << loaded.plugin.name() << " " << loaded.plugin.version() << " ("
                << loaded.plugin.path().string() << "), dimension " << loaded.model.dimension() << "\n"
                << "  study:       " << study.integrators.size()
                << " integrators to t_end = " << format_number(study.t_end)
                << (study.reference_q.empty() ? "" : ", with a reference") << "\n";
      for (const auto& integrator : study.integrators)
        std::cout << "    " << integrator.label << ": " << integrator.spec.scheme << ", order "
                  << integrator.spec.order.to_string() << ", t2 = " << format_number(integrator.spec.t2) << ", "
                  << integrator.steps.size() << " step counts " << integrator.steps.front() << ".."
                  << integrator.steps.back() << " (" << integrator.steps_from << ")\n";
      std::cout << "  output:      " << job.output_directory.string() << "\n";
      return to_int(ExitStatus::success);
    }
    const SingleRun& run = job.run();
    const IntegratorSpec& spec = run.integrator;
    std::cout << "valid: " << job_file << "\n"
              << "  model:       " << loaded.plugin.name() << " " << loaded.plugin.version() << " ("
              << loaded.plugin.path().string() << "), dimension " << loaded.model.dimension() << "\n"
              << "  parameters:  " << loaded.model.parameters().dump() << "\n"
              << "  integrator:  " << spec.scheme << ", order " << spec.order.to_string()
              << ", t2 = " << format_number(spec.t2) << ", H_" << (spec.form == HamiltonianForm::TTV ? "TTV" : "VVT")
              << "\n"
              << "  initial:     " << job.initial.count << " state" << (job.initial.count == 1 ? "" : "s") << " ("
              << job.initial.shape << ")\n"
              << "  time:        " << time_text(run.time) << "\n"
              << "  output:      " << job.output_directory.string() << ", trajectory every " << run.every
              << (run.every == 0 ? " (none)" : " steps") << "\n";
    return to_int(ExitStatus::success);
  } catch (const InvalidJob& error) {
    return report_invalid_job(error);
  }
}

}  // namespace nonsep::host::cli
