// SHA-256 (FIPS 180-4), for content addresses: the file store names files by their digest and
// the job queue recognises the same model bytes coming again.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace salient::server {

class Sha256 {
 public:
  Sha256();
  void update(std::string_view bytes);
  std::array<std::uint8_t, 32> digest();  // finishes: call once
  std::string hex();                      // finishes: call once

 private:
  void block(const std::uint8_t* p);
  std::uint32_t h_[8];
  std::uint8_t buffer_[64];
  std::size_t buffered_ = 0;
  std::uint64_t length_ = 0;
};

std::string sha256_hex(std::string_view bytes);

}  // namespace salient::server
