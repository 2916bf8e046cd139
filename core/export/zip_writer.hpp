// ZipWriter: a ZIP archive of stored (uncompressed) entries, enough for 3MF containers.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace salient::core {

class ZipWriter {
 public:
  void add(std::string name, std::string_view data);
  // The whole archive: local headers and data, central directory, end record.
  std::string finish() const;

 private:
  struct Entry {
    std::string name;
    std::uint32_t crc, size, offset;
  };
  std::string body_;
  std::vector<Entry> entries_;
};

}  // namespace salient::core
