#pragma once
// The formula cache's folder <root>/formula, held open by a descriptor, and the files in it, reached only through
// that descriptor without following links.
//
// The root: NONSEP_CACHE_DIR, else $XDG_CACHE_HOME/nonsep, else $HOME/.cache/nonsep (cache_directory(); created when
// missing, a link there followed: the user chose it). When formula/ cannot be created or written there, the
// fallback is <temporary folder>/nonsep-cache-<uid>, with a note through `say`. The fallback lies in a folder every
// user can write, so it is used only when it is a real folder (not a link), owned by this user, with no write bit
// for group or others; it is created with mode 0700. formula/ itself, wherever it is, is opened without following
// a link and must be owned by this user with no group or other write bit (as ssh checks ~/.ssh and ccache its
// cache). Anything else is FormulaCompileError naming the folder and what is wrong with it: nothing is compiled or
// loaded from a folder someone else can write.
//
// Inside formula/ every name is opened relative to the held descriptor with O_NOFOLLOW: locks (<key>.lock, a link
// or other non-file there is removed, never followed, and a fresh lock file made), entries (formula/<key>/, read
// with read_entry_file: a regular file or nothing, checked through its descriptor, so a FIFO, a device or a link
// to /dev/zero reads as "damaged", never blocks), and the folders a compile builds in.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>

namespace nonsep::host::formula {

class CacheFolder {
 public:
  // Opens (creating) the cache folder as above; throws FormulaCompileError.
  static CacheFolder open(const std::function<void(const std::string&)>& say);
  CacheFolder(CacheFolder&& other) noexcept;
  CacheFolder(const CacheFolder&) = delete;
  CacheFolder& operator=(const CacheFolder&) = delete;
  CacheFolder& operator=(CacheFolder&&) = delete;
  ~CacheFolder();

  const std::filesystem::path& path() const { return path_; }  // <root>/formula
  int descriptor() const { return descriptor_; }

  // The descriptor of the folder `name` (an entry, a build folder) inside, opened without following a link; -1
  // when it is missing or not a folder. The caller closes it.
  int open_folder(const std::string& name) const;
  // Creates the folder `name` inside (mode 0700); throws FormulaCompileError.
  void make_folder(const std::string& name) const;
  // Renames `from` to `to` inside, replacing an empty folder or a file there; false on failure.
  bool rename(const std::string& from, const std::string& to) const;
  // Removes `name` inside (a file, a link or a whole folder, whose links are removed, not followed).
  void remove(const std::string& name) const;

 private:
  CacheFolder(std::filesystem::path path, int descriptor) : path_(std::move(path)), descriptor_(descriptor) {}
  std::filesystem::path path_;
  int descriptor_;
};

// An exclusive flock on formula/<name>, created without following a link, for its lifetime.
class CacheLock {
 public:
  // wait = false: held() tells whether the lock was free. Throws FormulaCompileError when it cannot be made.
  CacheLock(const CacheFolder& folder, const std::string& name, bool wait = true);
  CacheLock(const CacheLock&) = delete;
  CacheLock& operator=(const CacheLock&) = delete;
  ~CacheLock();
  bool held() const { return held_; }

 private:
  int descriptor_ = -1;
  bool held_ = false;
};

// A descriptor, closed with the object.
class OpenFile {
 public:
  OpenFile() = default;
  explicit OpenFile(int descriptor) : descriptor_(descriptor) {}
  OpenFile(OpenFile&& other) noexcept : descriptor_(std::exchange(other.descriptor_, -1)) {}
  OpenFile& operator=(OpenFile&& other) noexcept;
  OpenFile(const OpenFile&) = delete;
  OpenFile& operator=(const OpenFile&) = delete;
  ~OpenFile();
  int descriptor() const { return descriptor_; }
  // The name that opens this very file again while the descriptor is open, wherever the file's path now leads:
  // /proc/self/fd/<descriptor>.
  std::filesystem::path reopen_path() const;

 private:
  int descriptor_ = -1;
};

// The regular file `name` in `folder`, held open, with its size and content hash (content_hash.hpp); nothing on the
// terms of read_entry_file.
struct CheckedFile {
  OpenFile file;
  std::uint64_t size = 0;
  std::uint64_t hash = 0;
};
std::optional<CheckedFile> open_entry_file(int folder, const std::string& name);

// The content of the regular file `name` in the folder `folder` (a descriptor), or nothing when it is missing, a
// link, not a regular file, longer than max_bytes or unreadable.
std::optional<std::string> read_entry_file(int folder, const std::string& name, std::size_t max_bytes);
// Its size and content hash (content_hash.hpp) on the same terms.
std::optional<std::pair<std::uint64_t, std::uint64_t>> entry_file_size_and_hash(int folder, const std::string& name);
// Creates the file `name` in `folder` holding `text`, every write checked and the file flushed to disk; throws
// FormulaCompileError naming `shown` (the file's path) and the reason (a full disk: "No space left on device").
void write_entry_file(int folder, const std::string& name, const std::string& text, const std::filesystem::path& shown);

// The folder named by the variables above, not yet created or checked.
std::filesystem::path cache_directory();

}  // namespace nonsep::host::formula
