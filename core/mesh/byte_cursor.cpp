// ByteCursor: truncation errors that say what was being read and where.
#include "core/mesh/byte_cursor.hpp"

#include "core/common/input_error.hpp"

namespace salient::core {

void ByteCursor::need(std::uint64_t bytes, std::string_view what) const {
  if (bytes > remaining()) {
    fail("file is truncated: " + std::string(what) + " needs " + std::to_string(bytes) + " bytes, only " +
         std::to_string(remaining()) + " left");
  }
}

void ByteCursor::skip(std::uint64_t bytes, std::string_view what) {
  need(bytes, what);
  pos_ += bytes;
}

void ByteCursor::fail(const std::string& message) const {
  fail_at(pos_, message);
}

void ByteCursor::fail_at(std::size_t offset, const std::string& message) const {
  throw InputError(source_, InputLocation::at_byte(offset), message);
}

}  // namespace salient::core
