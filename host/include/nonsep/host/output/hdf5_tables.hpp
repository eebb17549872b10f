#pragma once
// CSV tables and metadata in an HDF5 file (results.h5's /trajectories, /poincare, /lyapunov and root attributes).
//
// write_csv_table copies a CSV file of nonsep (csv.hpp's format) into `group` (created; a group of that name already
// there is replaced), one 1-D dataset per column, named by the header, one element per row:
//   - int64 for the columns named "trajectory" and "step" when every cell is an integer;
//   - float64 when every cell is a number (an empty cell: NaN; "nan", "inf" as append_number writes them), a column
//     of empty cells included;
//   - otherwise variable-length UTF-8 strings, the cells' text (quotes removed).
// Numeric datasets are chunked (at most 65536 rows a chunk) with shuffle and deflate, the chunks filtered by our code
// (shuffle_deflate.hpp) and written whole; strings chunked and deflated by HDF5.
// The file is read twice (types, then values, 65536 rows at a time), so tables larger than memory go through. A last
// line without its '\n' is not a row (what a hard kill cut off; python/nonsep/tables.py drops it too).
// Throws OutputError naming the CSV file and line (a row of another number of cells, an unclosed quote) or the HDF5
// file and what failed.
#include <cstdint>
#include <filesystem>
#include <string>

#include "nonsep/host/output/hdf5_file.hpp"

namespace nonsep::host {

void write_csv_table(const Hdf5File& file, const std::string& group, const std::filesystem::path& csv);

// Attributes of the object `object` (H5Oopen of a path, or the file's root group), replacing one of the same name:
// a UTF-8 string (variable length), a float64, a uint64. Throw OutputError.
void write_attribute(const Hdf5File& file, hid_t object, const std::string& name, const std::string& value);
void write_attribute(const Hdf5File& file, hid_t object, const std::string& name, double value);
void write_attribute(const Hdf5File& file, hid_t object, const std::string& name, std::uint64_t value);

}  // namespace nonsep::host
