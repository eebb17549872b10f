#include "output/results_h5.hpp"

#include <array>

#include "nonsep/host/output/hdf5_file.hpp"
#include "nonsep/host/output/hdf5_tables.hpp"
#include "nonsep/host/output/held_folder.hpp"

namespace nonsep::host {

void write_results_file(const std::filesystem::path& path, bool has_samples, const std::filesystem::path& directory,
                        const nlohmann::ordered_json& summary) {
  Hdf5File file = has_samples ? Hdf5File::open(path) : Hdf5File::create(path);
  write_csv_table(file, "/trajectories", directory / trajectories_file_name);
  for (const char* table : {"poincare", "lyapunov", "error_estimate", "frequency_spectra"}) {
    const std::filesystem::path csv = directory / (std::string(table) + ".csv");
    if (std::filesystem::exists(held_path(csv))) {
      write_csv_table(file, table, csv);
    } else if (H5Lexists(file.id(), table, H5P_DEFAULT) > 0) {
      file.check(H5Ldelete(file.id(), table, H5P_DEFAULT), std::string("remove the stale group /") + table);
    }
  }

  const Hdf5Handle root = file.own(H5Oopen(file.id(), "/", H5P_DEFAULT), H5Oclose, "open the root group");
  const auto attribute = [&](const std::string& name, const auto& value) {
    write_attribute(file, root.get(), name, value);
  };
  const nlohmann::ordered_json &model = summary["model"], &time = summary["time"];
  unsigned major = 0, minor = 0, release = 0;
  file.check(H5get_libversion(&major, &minor, &release), "read the HDF5 library's version");
  attribute("nonsep_version", std::string(NONSEP_VERSION));
  attribute("hdf5_version", std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(release));
  attribute("format_version", results_format_version);
  attribute("model", model["plugin"].get<std::string>());
  attribute("plugin_version", model["version"].get<std::string>());
  attribute("parameters", model["parameters"].dump());  // a sweep's parameters with their values
  attribute("integrator", summary["integrator"].dump());
  attribute("hamiltonian", summary["hamiltonian"].get<std::string>());
  attribute("dt", time["dt"].get<double>());
  attribute("steps", time["steps"].get<std::uint64_t>());
  attribute("t_end", time["t_end"].get<double>());
  attribute("every", summary["output"]["every"].get<std::uint64_t>());
  attribute("dimension", model["dimension"].get<std::uint64_t>());
  attribute("trajectories", summary["trajectories"].get<std::uint64_t>());
  attribute("summary", summary.dump(2) + "\n");
  file.close();
}

}  // namespace nonsep::host
