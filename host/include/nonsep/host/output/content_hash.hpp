#pragma once
// The one content hash of nonsep's files: 64-bit FNV-1a, written as 16 hexadecimal digits. It identifies content
// (a plugin file in the job fingerprint, the prefix of trajectory.csv and the body of checkpoint.json in a
// checkpoint); it detects accidental change and mixing of files, not tampering by someone who means it.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace nonsep::host {

inline constexpr std::uint64_t content_hash_start = 14695981039346656037ull;

// The hash of `bytes` continuing from `hash` (content_hash_start for the first piece).
inline std::uint64_t content_hash(std::string_view bytes, std::uint64_t hash = content_hash_start) {
  for (unsigned char c : bytes) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  return hash;
}

inline std::string content_hash_hex(std::uint64_t hash) {
  char digits[17];
  std::snprintf(digits, sizeof digits, "%016llx", static_cast<unsigned long long>(hash));
  return digits;
}

// The hash of the first `size` bytes of the file at `path` (all of it when `size` is empty), or nothing when the
// file cannot be read or is shorter than `size`.
std::optional<std::uint64_t> file_content_hash(const std::filesystem::path& path,
                                               std::optional<std::uint64_t> size = std::nullopt);
// The same for an open file (read with pread: the descriptor's offset does not move).
std::optional<std::uint64_t> descriptor_content_hash(int descriptor, std::optional<std::uint64_t> size = std::nullopt);

}  // namespace nonsep::host
