#pragma once
// results.h5 through the HDF5 C API (only in builds with HDF5: NONSEP_HAVE_HDF5). Hdf5Handle owns one identifier
// and closes it with the function of its kind; Hdf5File owns an open file and turns every failed HDF5 call into
// nonsep's OutputError: "<file>: cannot <what> (<HDF5's innermost reason>)". HDF5's own printing of its error stack
// to stderr is switched off (H5Eset_auto) the first time a file is created or opened: the OutputError says it once.
//
// Every call must come from one thread at a time (Debian's HDF5 is not built thread-safe); nonsep makes them all on
// the driver's thread.
#include <hdf5.h>

#include <filesystem>
#include <span>
#include <string>
#include <utility>

namespace nonsep::host {

class Hdf5Handle {
 public:
  using Close = herr_t (*)(hid_t);
  Hdf5Handle() = default;
  Hdf5Handle(hid_t id, Close close) : id_(id), close_(close) {}
  Hdf5Handle(Hdf5Handle&& other) noexcept : id_(std::exchange(other.id_, H5I_INVALID_HID)), close_(other.close_) {}
  Hdf5Handle& operator=(Hdf5Handle&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = std::exchange(other.id_, H5I_INVALID_HID);
      close_ = other.close_;
    }
    return *this;
  }
  Hdf5Handle(const Hdf5Handle&) = delete;
  Hdf5Handle& operator=(const Hdf5Handle&) = delete;
  ~Hdf5Handle() { reset(); }

  hid_t get() const { return id_; }
  // Gives up ownership: the caller closes.
  hid_t release() { return std::exchange(id_, H5I_INVALID_HID); }
  void reset() {
    if (id_ >= 0 && close_) close_(id_);  // a failure to close a group or a dataspace has nothing left to report
    id_ = H5I_INVALID_HID;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Close close_ = nullptr;
};

class Hdf5File {
 public:
  // Creates `path`, replacing a file that is there, with `access` as its file access property list (H5P_DEFAULT:
  // the sec2 driver; an MPI-IO list for ranks writing one file). Objects created in it record no times
  // (H5Pset_obj_track_times false), so its bytes do not depend on when it was written. Throws OutputError.
  static Hdf5File create(const std::filesystem::path& path, hid_t access = H5P_DEFAULT);
  // Opens the existing file at `path` for reading and writing. Throws OutputError (a missing file, not HDF5, ...).
  static Hdf5File open(const std::filesystem::path& path, hid_t access = H5P_DEFAULT);

  hid_t id() const { return file_.get(); }
  const std::filesystem::path& path() const { return path_; }

  // `result` when it is a valid identifier or status (>= 0); otherwise throws OutputError naming the file, `what`
  // could not be done and HDF5's reason.
  template <class Result>
  Result check(Result result, const std::string& what) const {
    if (result < 0) fail(what);
    return result;
  }
  // An identifier from H5?create/H5?open, owned. Throws OutputError as check().
  Hdf5Handle own(hid_t id, Hdf5Handle::Close close, const std::string& what) const {
    return Hdf5Handle(check(id, what), close);
  }
  [[noreturn]] void fail(const std::string& what) const;

  // Writes everything cached (metadata and chunks) to the file. Throws OutputError.
  void flush();
  // Closes the file, reporting a failure (the destructor closes too, silently). Objects still open in it (datasets
  // of Hdf5Handle) keep it open until they are closed (HDF5's default "weak" close). Throws OutputError.
  void close();

 private:
  Hdf5File(std::filesystem::path path, hid_t id) : path_(std::move(path)), file_(id, H5Fclose) {}
  std::filesystem::path path_;
  Hdf5Handle file_;
};

// Object creation property lists for groups and datasets that record no times (see Hdf5File::create).
Hdf5Handle untimed_group_properties(const Hdf5File& file);
Hdf5Handle untimed_dataset_properties(const Hdf5File& file);

class ShuffleDeflate;
// Writes the chunk of `dataset` at `offset` (its first element's coordinates) whole: `chunk` holds all its elements
// (the chunk's shape, padded past the dataset's end), little-endian, `element_size` bytes each, as the dataset stores
// them; `filter` shuffles and deflates them (shuffle_deflate.hpp), which must be the dataset's declared filters, and
// H5Dwrite_chunk writes the result. Not under MPI-IO (HDF5 1.10 refuses). Throws OutputError saying `what` failed.
void write_filtered_chunk(const Hdf5File& file, hid_t dataset, std::span<const hsize_t> offset,
                          std::span<const unsigned char> chunk, std::size_t element_size, ShuffleDeflate& filter,
                          const std::string& what);

}  // namespace nonsep::host
