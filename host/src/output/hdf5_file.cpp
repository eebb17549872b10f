#include "nonsep/host/output/hdf5_file.hpp"

#include <bit>

#include "nonsep/host/output/atomic_files.hpp"
#include "nonsep/host/output/held_folder.hpp"
#include "nonsep/host/output/shuffle_deflate.hpp"

namespace nonsep::host {

namespace {

void silence_hdf5_error_printing() {
  static const bool silenced = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)silenced;
}

// The innermost (most specific) description on HDF5's error stack of this thread, e.g. "unable to open file".
std::string hdf5_reason() {
  std::string reason;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned, const H5E_error2_t* error, void* data) -> herr_t {
        auto& text = *static_cast<std::string*>(data);
        if (text.empty() && error->desc && *error->desc) text = error->desc;
        return 0;
      },
      &reason);
  H5Eclear2(H5E_DEFAULT);
  return reason.empty() ? "HDF5 gave no reason" : reason;
}

Hdf5Handle untimed_properties(const Hdf5File& file, hid_t kind) {
  Hdf5Handle properties = file.own(H5Pcreate(kind), H5Pclose, "create a property list");
  file.check(H5Pset_obj_track_times(properties.get(), false), "turn off the recording of times");
  return properties;
}

}  // namespace

void Hdf5File::fail(const std::string& what) const {
  throw OutputError(path_.string() + ": cannot " + what + " (HDF5: " + hdf5_reason() + ")");
}

Hdf5File Hdf5File::create(const std::filesystem::path& path, hid_t access) {
  silence_hdf5_error_printing();
  Hdf5File file(path, H5I_INVALID_HID);
  // The root group is created with the file: its creation list (which is also a group's) must say "no times".
  const Hdf5Handle creation = untimed_properties(file, H5P_FILE_CREATE);
  file.file_ = file.own(H5Fcreate(held_path(path).c_str(), H5F_ACC_TRUNC, creation.get(), access), H5Fclose,
                        "create the HDF5 file");
  return file;
}

Hdf5File Hdf5File::open(const std::filesystem::path& path, hid_t access) {
  silence_hdf5_error_printing();
  Hdf5File file(path, H5I_INVALID_HID);
  file.file_ =
      file.own(H5Fopen(held_path(path).c_str(), H5F_ACC_RDWR, access), H5Fclose, "open the HDF5 file for writing");
  return file;
}

void Hdf5File::flush() { check(H5Fflush(file_.get(), H5F_SCOPE_LOCAL), "write its cached data to the file"); }

void Hdf5File::close() {
  if (file_.get() < 0) return;
  // Released first, so that a failing close is not tried again by the destructor.
  check(H5Fclose(file_.release()), "close the file");
}

Hdf5Handle untimed_group_properties(const Hdf5File& file) { return untimed_properties(file, H5P_GROUP_CREATE); }
Hdf5Handle untimed_dataset_properties(const Hdf5File& file) { return untimed_properties(file, H5P_DATASET_CREATE); }

void write_filtered_chunk(const Hdf5File& file, hid_t dataset, std::span<const hsize_t> offset,
                          std::span<const unsigned char> chunk, std::size_t element_size, ShuffleDeflate& filter,
                          const std::string& what) {
  static_assert(std::endian::native == std::endian::little, "the chunks are written in the stored (LE) byte order");
  const std::span<const unsigned char> bytes = filter.filter(chunk, element_size);
  file.check(H5Dwrite_chunk(dataset, H5P_DEFAULT, 0, offset.data(), bytes.size(), bytes.data()), what);
}

}  // namespace nonsep::host
