#include "nonsep/host/output/hdf5_tables.hpp"

#include <algorithm>
#include <charconv>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "nonsep/host/number_format.hpp"
#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/csv_reader.hpp"
#include "nonsep/host/output/shuffle_deflate.hpp"

namespace nonsep::host {

namespace {

constexpr std::size_t rows_per_block = 65536;

bool is_integer(const std::string& cell) {
  std::int64_t value = 0;
  const auto result = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  return !cell.empty() && result.ec == std::errc() && result.ptr == cell.data() + cell.size();
}

enum class Kind { integer, number, text };

struct Column {
  std::string name;
  Kind kind = Kind::number;
  Hdf5Handle dataset;
};

// The header and each column's kind, and the number of rows.
std::vector<Column> survey(const std::filesystem::path& csv, std::uint64_t& rows) {
  CsvReader reader(csv, "to copy it into results.h5");
  std::vector<std::string> cells;
  if (!reader.next(cells)) throw OutputError(csv.string() + " has no header line to copy into results.h5");
  std::vector<Column> columns(cells.size());
  for (std::size_t k = 0; k < cells.size(); ++k) {
    columns[k].name = cells[k];
    columns[k].kind = cells[k] == "trajectory" || cells[k] == "step" ? Kind::integer : Kind::number;
  }
  rows = 0;
  while (reader.next(cells)) {
    if (cells.size() != columns.size())
      throw OutputError(csv.string() + ":" + std::to_string(reader.line()) + ": found " + std::to_string(cells.size()) +
                        " cells; expected " + std::to_string(columns.size()) + ", as in the header");
    for (std::size_t k = 0; k < cells.size(); ++k) {
      Kind& kind = columns[k].kind;
      if (kind == Kind::integer && !is_integer(cells[k])) kind = Kind::number;
      if (kind == Kind::number && !cells[k].empty() && !parse_number(cells[k])) kind = Kind::text;
    }
    ++rows;
  }
  return columns;
}

Hdf5Handle utf8_string_type(const Hdf5File& file) {
  Hdf5Handle type = file.own(H5Tcopy(H5T_C_S1), H5Tclose, "make a string type");
  file.check(H5Tset_size(type.get(), H5T_VARIABLE), "make a string type");
  file.check(H5Tset_cset(type.get(), H5T_CSET_UTF8), "make a string type");
  return type;
}

Hdf5Handle create_column(const Hdf5File& file, hid_t group, const std::string& where, const Column& column, hid_t type,
                         std::uint64_t rows) {
  const std::string what = "create " + where + "/" + column.name;
  // A table without rows still gets its (empty) columns: chunked datasets need a chunk of at least one element,
  // which only an extendible dataspace allows when there are none.
  const hsize_t size = rows, unlimited = H5S_UNLIMITED, chunk = std::clamp<hsize_t>(rows, 1, rows_per_block);
  const Hdf5Handle space = file.own(H5Screate_simple(1, &size, rows == 0 ? &unlimited : nullptr), H5Sclose, what);
  const Hdf5Handle properties = untimed_dataset_properties(file);
  file.check(H5Pset_chunk(properties.get(), 1, &chunk), what);
  if (column.kind != Kind::text) file.check(H5Pset_shuffle(properties.get()), what);
  file.check(H5Pset_deflate(properties.get(), 1), what);
  return file.own(H5Dcreate2(group, column.name.c_str(), type, space.get(), H5P_DEFAULT, properties.get(), H5P_DEFAULT),
                  H5Dclose, what);
}

void write_rows(const Hdf5File& file, const Column& column, hid_t memory_type, hsize_t first, hsize_t count,
                const void* values, const std::string& where) {
  const std::string what = "write " + where + "/" + column.name;
  const Hdf5Handle space = file.own(H5Dget_space(column.dataset.get()), H5Sclose, what);
  file.check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, &first, nullptr, &count, nullptr), what);
  const Hdf5Handle memory = file.own(H5Screate_simple(1, &count, nullptr), H5Sclose, what);
  file.check(H5Dwrite(column.dataset.get(), memory_type, memory.get(), space.get(), H5P_DEFAULT, values), what);
}

// The numbers of a block: one chunk, whole (shuffle_deflate.hpp); zero past the last row of the last chunk.
template <class Number>
void write_chunk(const Hdf5File& file, const Column& column, std::vector<Number>& values, hsize_t first, hsize_t count,
                 ShuffleDeflate& filter, const std::string& where) {
  std::fill(values.begin() + static_cast<std::ptrdiff_t>(count), values.end(), Number{0});
  write_filtered_chunk(file, column.dataset.get(), std::span(&first, 1),
                       std::span(reinterpret_cast<const unsigned char*>(values.data()), values.size() * sizeof(Number)),
                       sizeof(Number), filter, "write " + where + "/" + column.name);
}

// Writes the block of rows `cells` ([row][column]) starting at row `first`, a multiple of `chunk` (the datasets'
// chunk: the block's size, or more for the last block); `changed` throws (a cell no longer of its column's kind: the
// file changed between the two readings).
template <class Changed>
void write_block(const Hdf5File& file, std::vector<Column>& columns, hid_t string_type, ShuffleDeflate& filter,
                 std::span<const std::vector<std::string>> block, std::uint64_t first, hsize_t chunk,
                 const std::string& where, Changed&& changed) {
  const hsize_t count = block.size();
  std::vector<std::int64_t> integers(chunk);
  std::vector<double> numbers(chunk);
  std::vector<const char*> texts(block.size());
  for (std::size_t k = 0; k < columns.size(); ++k) {
    const Column& column = columns[k];
    for (std::size_t r = 0; r < block.size(); ++r) {
      const std::string& cell = block[r][k];
      if (column.kind == Kind::integer) {
        if (!is_integer(cell)) changed();
        std::from_chars(cell.data(), cell.data() + cell.size(), integers[r]);
      } else if (column.kind == Kind::number) {
        const std::optional<double> number =
            cell.empty() ? std::numeric_limits<double>::quiet_NaN() : parse_number(cell);
        if (!number) changed();
        numbers[r] = *number;
      } else {
        texts[r] = cell.c_str();
      }
    }
    if (column.kind == Kind::integer)
      write_chunk(file, column, integers, first, count, filter, where);
    else if (column.kind == Kind::number)
      write_chunk(file, column, numbers, first, count, filter, where);
    else
      write_rows(file, column, string_type, first, count, texts.data(), where);
  }
}

void replace_attribute_if_there(const Hdf5File& file, hid_t object, const std::string& name) {
  if (file.check(H5Aexists(object, name.c_str()), "look for the attribute " + name) > 0)
    file.check(H5Adelete(object, name.c_str()), "replace the attribute " + name);
}

void write_scalar_attribute(const Hdf5File& file, hid_t object, const std::string& name, hid_t stored, hid_t memory,
                            const void* value) {
  replace_attribute_if_there(file, object, name);
  const std::string what = "write the attribute " + name;
  const Hdf5Handle space = file.own(H5Screate(H5S_SCALAR), H5Sclose, what);
  const Hdf5Handle attribute =
      file.own(H5Acreate2(object, name.c_str(), stored, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose, what);
  file.check(H5Awrite(attribute.get(), memory, value), what);
}

}  // namespace

void write_csv_table(const Hdf5File& file, const std::string& group, const std::filesystem::path& csv) {
  std::uint64_t rows = 0;
  std::vector<Column> columns = survey(csv, rows);
  const std::string where = group.starts_with('/') ? group : "/" + group;
  if (file.check(H5Lexists(file.id(), where.c_str(), H5P_DEFAULT), "look for " + where) > 0)
    file.check(H5Ldelete(file.id(), where.c_str(), H5P_DEFAULT), "replace " + where);
  const Hdf5Handle properties = untimed_group_properties(file);
  const Hdf5Handle handle = file.own(H5Gcreate2(file.id(), where.c_str(), H5P_DEFAULT, properties.get(), H5P_DEFAULT),
                                     H5Gclose, "create the group " + where);
  const Hdf5Handle string_type = utf8_string_type(file);
  for (Column& column : columns) {
    const hid_t stored = column.kind == Kind::integer  ? H5T_STD_I64LE
                         : column.kind == Kind::number ? H5T_IEEE_F64LE
                                                       : string_type.get();
    column.dataset = create_column(file, handle.get(), where, column, stored, rows);
  }
  const auto changed = [&] {
    throw OutputError(csv.string() + " changed while it was copied into " + file.path().string());
  };
  CsvReader reader(csv, "to copy it into results.h5");
  const hsize_t chunk = std::min<std::uint64_t>(rows, rows_per_block);
  ShuffleDeflate filter(1);
  std::vector<std::vector<std::string>> block(chunk);
  std::vector<std::string> cells;
  reader.next(cells);  // the header
  std::uint64_t first = 0;
  for (bool more = true; more;) {
    std::size_t used = 0;
    while (used < block.size() && (more = reader.next(cells))) {
      if (cells.size() != columns.size()) changed();
      std::swap(block[used++], cells);  // the row's strings change hands; no cell is copied
    }
    if (first + used > rows) changed();
    if (used > 0)
      write_block(file, columns, string_type.get(), filter, std::span(block).first(used), first, chunk, where, changed);
    first += used;
    more = more && used > 0;
  }
}

void write_attribute(const Hdf5File& file, hid_t object, const std::string& name, const std::string& value) {
  const Hdf5Handle type = utf8_string_type(file);
  const char* text = value.c_str();
  write_scalar_attribute(file, object, name, type.get(), type.get(), &text);
}

void write_attribute(const Hdf5File& file, hid_t object, const std::string& name, double value) {
  write_scalar_attribute(file, object, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value);
}

void write_attribute(const Hdf5File& file, hid_t object, const std::string& name, std::uint64_t value) {
  write_scalar_attribute(file, object, name, H5T_STD_U64LE, H5T_NATIVE_UINT64, &value);
}

}  // namespace nonsep::host
