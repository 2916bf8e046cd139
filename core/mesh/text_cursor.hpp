// TextCursor: line and token reading over an in-memory text file, with line numbers for errors.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "core/common/input_error.hpp"

namespace salient::core {

class TextCursor {
 public:
  TextCursor(std::string_view text, std::string source, std::uint64_t first_line = 1);

  // The next line without its terminator ("\n", "\r\n" or "\r"); false at the end of the text.
  bool next_line(std::string_view& line);
  // The next whitespace-separated token, crossing lines; false at the end of the text.
  bool next_token(std::string_view& token);
  // Skips to the end of the current line (for token-based reading).
  void skip_rest_of_line();
  // Like next_token, but a missing token is an error that says what was expected.
  std::string_view expect_token(std::string_view what);

  // 1-based number of the line last read from.
  std::uint64_t line_number() const { return line_; }
  std::size_t offset() const { return pos_; }
  std::size_t remaining() const { return text_.size() - pos_; }
  const std::string& source() const { return source_; }

  [[noreturn]] void fail(const std::string& message) const;

  double parse_double(std::string_view token, std::string_view what) const;
  std::int64_t parse_int(std::string_view token, std::string_view what) const;

 private:
  std::string_view text_;
  std::string source_;
  std::size_t pos_ = 0;
  std::uint64_t line_;
  bool started_ = false;
};

// Splits one line into whitespace-separated tokens.
class LineTokens {
 public:
  explicit LineTokens(std::string_view line) : rest_(line) {}
  bool next(std::string_view& token);
  std::string_view rest() const { return rest_; }

 private:
  std::string_view rest_;
};

// Number parsing shared by the text formats: false if `token` is not a whole number.
bool parse_number(std::string_view token, double& value);
bool parse_number(std::string_view token, std::int64_t& value);

}  // namespace salient::core
