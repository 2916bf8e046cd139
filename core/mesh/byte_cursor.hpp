// ByteCursor: bounds-checked little/big-endian reads from an in-memory binary file.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

namespace salient::core {

enum class Endian { little, big };

class ByteCursor {
 public:
  ByteCursor(std::string_view data, std::string source, std::size_t start = 0)
      : data_(data), source_(std::move(source)), pos_(start) {}

  std::size_t offset() const { return pos_; }
  std::size_t remaining() const { return data_.size() - pos_; }
  const std::string& source() const { return source_; }

  // Throws InputError("truncated ...") unless `bytes` more bytes are there.
  void need(std::uint64_t bytes, std::string_view what) const;
  void skip(std::uint64_t bytes, std::string_view what);

  template <typename T>
  T read(Endian endian, std::string_view what) {
    need(sizeof(T), what);
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, data_.data() + pos_, sizeof(T));
    if (endian == Endian::big) {
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    }
    T value;
    std::memcpy(&value, raw, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }

  [[noreturn]] void fail(const std::string& message) const;
  [[noreturn]] void fail_at(std::size_t offset, const std::string& message) const;

 private:
  std::string_view data_;
  std::string source_;
  std::size_t pos_;
};

}  // namespace salient::core
