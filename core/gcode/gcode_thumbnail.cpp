// thumbnail_block and read_thumbnails, with the base64 (RFC 4648, padded) they need.
#include "core/gcode/gcode_thumbnail.hpp"

#include <array>
#include <cstdio>
#include <sstream>

#include "core/common/input_error.hpp"

namespace salient::core {
namespace {

constexpr std::string_view kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
// PrusaSlicer's max_row_length: lines stay short for firmwares with small line buffers.
constexpr std::size_t kRowLength = 78;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

}  // namespace

std::string base64_encode(std::string_view bytes) {
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 3; ++k) v = v << 8 | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? kAlphabet[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

std::string base64_decode(std::string_view text, const std::string& source) {
  if (text.size() % 4 != 0) throw InputError(source, {}, "base64 length is not a multiple of 4");
  std::string out;
  out.reserve(text.size() / 4 * 3);
  for (std::size_t i = 0; i < text.size(); i += 4) {
    std::uint32_t v = 0;
    int pad = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      const char c = text[i + k];
      const std::size_t at = kAlphabet.find(c);
      const bool padding = c == '=' && i + 4 == text.size() && k >= 2;
      if (at == std::string_view::npos && !padding)
        throw InputError(source, {}, std::string("invalid base64 character '") + c + "'");
      if (pad > 0 && !padding) throw InputError(source, {}, "base64 data after padding");
      pad += padding;
      v = v << 6 | (padding ? 0u : static_cast<std::uint32_t>(at));
    }
    for (int k = 0; k < 3 - pad; ++k) out += static_cast<char>((v >> (16 - 8 * k)) & 0xff);
  }
  return out;
}

std::string thumbnail_block(const GcodeThumbnail& t) {
  const std::string data = base64_encode(t.png);
  std::ostringstream out;
  out << ";\n; thumbnail begin " << t.width << "x" << t.height << " " << data.size() << "\n";
  for (std::size_t at = 0; at < data.size(); at += kRowLength)
    out << "; " << data.substr(at, kRowLength) << "\n";
  out << "; thumbnail end\n;\n";
  return out.str();
}

std::vector<GcodeThumbnail> read_thumbnails(std::string_view gcode, const std::string& source) {
  std::vector<GcodeThumbnail> found;
  std::istringstream in{std::string(gcode)};
  std::string line;
  bool inside = false;
  std::size_t length = 0;
  std::string data;
  GcodeThumbnail current;
  while (std::getline(in, line)) {
    std::string_view l = trim(line);
    if (l.empty() || l.front() != ';') continue;
    l = trim(l.substr(1));
    if (l.starts_with("thumbnail begin ")) {
      char tail = 0;
      if (std::sscanf(std::string(l).c_str(), "thumbnail begin %dx%d %zu%c", &current.width, &current.height,
                      &length, &tail) != 3)
        throw InputError(source, {}, "malformed thumbnail header '" + std::string(l) + "'");
      inside = true;
      data.clear();
    } else if (inside && l == "thumbnail end") {
      if (data.size() != length)
        throw InputError(source, {},
                         "thumbnail " + std::to_string(current.width) + "x" + std::to_string(current.height) +
                             " says " + std::to_string(length) + " characters, has " +
                             std::to_string(data.size()));
      current.png = base64_decode(data, source);
      found.push_back(std::move(current));
      current = {};
      inside = false;
    } else if (inside) {
      data += l;
    }
  }
  if (inside) throw InputError(source, {}, "thumbnail block without '; thumbnail end'");
  return found;
}

}  // namespace salient::core
