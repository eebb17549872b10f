#pragma once
// The names of the files a run writes at its end in its output folder; what they hold is said where they are
// assembled (launch/run_summary.hpp) and, for results.h5, where it is written (output/results_h5.hpp).
namespace nonsep::host {

inline constexpr const char* summary_file_name = "summary.json";
inline constexpr const char* trajectories_file_name = "trajectories.csv";
inline constexpr const char* results_file_name = "results.h5";  // output.format "hdf5"

}  // namespace nonsep::host
