// TextCursor: line and token reading with line numbers.
#include "core/mesh/text_cursor.hpp"

#include <charconv>

namespace salient::core {
namespace {

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}

std::string quoted(std::string_view token) {
  constexpr std::size_t max_shown = 40;
  std::string shown(token.substr(0, max_shown));
  for (char& c : shown)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
  return "'" + shown + (token.size() > max_shown ? "...'" : "'");
}

}  // namespace

bool parse_number(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return ec == std::errc() && ptr == end && !token.empty();
}

bool parse_number(std::string_view token, std::int64_t& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return ec == std::errc() && ptr == end && !token.empty();
}

TextCursor::TextCursor(std::string_view text, std::string source, std::uint64_t first_line)
    : text_(text), source_(std::move(source)), line_(first_line) {}

bool TextCursor::next_line(std::string_view& line) {
  if (pos_ >= text_.size()) return false;
  if (started_) ++line_;
  started_ = true;
  std::size_t end = pos_;
  while (end < text_.size() && text_[end] != '\n' && text_[end] != '\r') ++end;
  line = text_.substr(pos_, end - pos_);
  if (end < text_.size() && text_[end] == '\r') ++end;
  if (end < text_.size() && text_[end] == '\n') ++end;
  pos_ = end;
  return true;
}

bool TextCursor::next_token(std::string_view& token) {
  if (!started_) started_ = true;
  const std::uint64_t line_before = line_;
  while (pos_ < text_.size() && is_space(text_[pos_])) {
    if (text_[pos_] == '\n') ++line_;
    ++pos_;
  }
  if (pos_ >= text_.size()) {
    line_ = line_before;  // an "unexpected end of file" belongs to the last line with content
    return false;
  }
  std::size_t end = pos_;
  while (end < text_.size() && !is_space(text_[end])) ++end;
  token = text_.substr(pos_, end - pos_);
  pos_ = end;
  return true;
}

void TextCursor::skip_rest_of_line() {
  while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
}

std::string_view TextCursor::expect_token(std::string_view what) {
  std::string_view token;
  if (!next_token(token)) fail("unexpected end of file: expected " + std::string(what));
  return token;
}

void TextCursor::fail(const std::string& message) const {
  throw InputError(source_, InputLocation::at_line(line_), message);
}

double TextCursor::parse_double(std::string_view token, std::string_view what) const {
  double value = 0;
  if (!parse_number(token, value))
    fail("expected a number for " + std::string(what) + ", got " + quoted(token));
  return value;
}

std::int64_t TextCursor::parse_int(std::string_view token, std::string_view what) const {
  std::int64_t value = 0;
  if (!parse_number(token, value))
    fail("expected an integer for " + std::string(what) + ", got " + quoted(token));
  return value;
}

bool LineTokens::next(std::string_view& token) {
  std::size_t i = 0;
  while (i < rest_.size() && is_space(rest_[i])) ++i;
  if (i == rest_.size()) {
    rest_ = {};
    return false;
  }
  std::size_t end = i;
  while (end < rest_.size() && !is_space(rest_[end])) ++end;
  token = rest_.substr(i, end - i);
  rest_.remove_prefix(end);
  return true;
}

}  // namespace salient::core
