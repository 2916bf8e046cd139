// ZipReader: the entries of a ZIP archive held in memory, stored or deflated — enough to read a
// 3MF container (ours, PrusaSlicer's). No ZIP64, no encryption, no multi-disk archives.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace salient::core {

class ZipReader {
 public:
  // Reads the central directory of `archive` (which must outlive the reader). Throws InputError
  // naming `name` and the byte at fault for a truncated or malformed archive.
  ZipReader(std::string_view archive, std::string name);

  std::vector<std::string> names() const;
  bool contains(std::string_view entry) const;

  // The entry's bytes, or nullopt when there is no such entry. Throws InputError for an
  // unsupported method, a wrong CRC-32, a size that disagrees with the directory, or an entry
  // larger than `max_size` bytes once inflated (a zip bomb is refused before it is inflated
  // past the bound, whatever its directory claims).
  std::optional<std::string> read(std::string_view entry, std::size_t max_size = 64u << 20) const;

 private:
  struct Entry {
    std::string name;
    std::uint16_t method = 0, flags = 0;
    std::uint32_t crc = 0, compressed = 0, size = 0, local_offset = 0;
  };
  std::string_view archive_;
  std::string name_;
  std::vector<Entry> entries_;
};

}  // namespace salient::core
