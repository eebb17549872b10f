#include "nonsep/host/output/held_folder.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <mutex>
#include <optional>

#include "nonsep/host/output/atomic_files.hpp"

namespace nonsep::host {

namespace {

std::mutex registry_mutex;
std::map<std::string, int>& registry() {
  static std::map<std::string, int> folders;  // key: the held folder's path, lexically normal, no trailing '/'
  return folders;
}

std::string key_of(const std::filesystem::path& path) {
  std::string key = path.lexically_normal().string();
  while (key.size() > 1 && key.back() == '/') key.pop_back();
  return key;
}

// The held folder that is `path` or the nearest of its ancestors, with the rest of `path` below it.
struct Anchor {
  int descriptor;
  std::filesystem::path rest;
};
std::optional<Anchor> anchor_of(const std::filesystem::path& path) {
  const std::filesystem::path normal = path.lexically_normal();
  const std::lock_guard lock(registry_mutex);
  for (std::filesystem::path folder = normal; !folder.empty(); folder = folder.parent_path()) {
    if (const auto held = registry().find(key_of(folder)); held != registry().end())
      return Anchor{held->second, normal.lexically_relative(folder)};
    if (folder == folder.parent_path()) break;
  }
  return std::nullopt;
}

// Opens the folder `rest` below `descriptor`, one name at a time, following no link. -1 and errno on failure.
int open_beneath(int descriptor, const std::filesystem::path& rest) {
  int current = ::dup(descriptor);
  for (const auto& part : rest) {
    if (current < 0 || part == ".") continue;
    const int next = ::openat(current, part.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    const int error = errno;
    ::close(current);
    current = next;
    errno = error;
  }
  return current;
}

}  // namespace

HeldFolder::HeldFolder(const std::filesystem::path& path) : key_(key_of(path)) {
  const auto fail = [&](const std::string& what, const std::string& reason) {
    throw OutputError("cannot " + what + " the output folder " + path.string() + ": " + reason);
  };
  if (const auto anchor = anchor_of(path)) {
    const int parent = open_beneath(anchor->descriptor, anchor->rest.parent_path());
    if (parent < 0) fail("create", std::strerror(errno));
    const int made = ::mkdirat(parent, anchor->rest.filename().c_str(), 0755);
    const int error = errno;
    if (made == 0 || error == EEXIST)
      descriptor_ = ::openat(parent, anchor->rest.filename().c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
    const int open_error = errno;
    ::close(parent);
    if (made != 0 && error != EEXIST) fail("create", std::strerror(error));
    if (descriptor_ < 0)
      fail("open",
           open_error == ELOOP || open_error == ENOTDIR ? "it is not a folder (a link?)" : std::strerror(open_error));
  } else {
    std::error_code error;
    std::filesystem::create_directories(path, error);
    if (error) fail("create", error.message());
    descriptor_ = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (descriptor_ < 0) fail("open", std::strerror(errno));
  }
  // A second hold of one folder (refused by RunFolder's lock right after) leaves the first registered.
  const std::lock_guard lock(registry_mutex);
  registry().emplace(key_, descriptor_);
}

HeldFolder::~HeldFolder() {
  {
    const std::lock_guard lock(registry_mutex);
    if (const auto held = registry().find(key_); held != registry().end() && held->second == descriptor_)
      registry().erase(held);
  }
  ::close(descriptor_);
}

FileLocation::FileLocation(const std::filesystem::path& path) : folder_(AT_FDCWD), name_(path.string()) {
  const auto anchor = anchor_of(path.parent_path());
  if (!anchor) return;
  name_ = path.filename().string();
  if (anchor->rest.empty() || anchor->rest == ".") {
    folder_ = anchor->descriptor;
    return;
  }
  folder_ = open_beneath(anchor->descriptor, anchor->rest);
  if (folder_ < 0)
    throw OutputError("cannot reach " + path.string() + ": " + (anchor->rest).string() + " in the output folder is " +
                      (errno == ELOOP || errno == ENOTDIR ? "not a folder (a link?)" : std::strerror(errno)));
  owned_ = true;
}

FileLocation::~FileLocation() {
  if (owned_) ::close(folder_);
}

std::filesystem::path held_path(const std::filesystem::path& path) {
  const auto anchor = anchor_of(path);
  if (!anchor) return path;
  std::filesystem::path proc = "/proc/self/fd/" + std::to_string(anchor->descriptor);
  return anchor->rest.empty() || anchor->rest == "." ? proc : proc / anchor->rest;
}

}  // namespace nonsep::host
