#include "server/http/multipart.hpp"

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace salient::server {
namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return std::tolower(c); });
  return out;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// The value of `key=` in a header's parameters (`form-data; name="a"; filename="b c"`): quoted,
// with backslash escapes, or bare. Parameters are read one by one, so text inside a quoted value
// ("a; name=x") is never taken for a parameter of its own.
std::optional<std::string> parameter(std::string_view header, std::string_view key) {
  std::size_t at = header.find(';');
  while (at != std::string_view::npos && at < header.size()) {
    ++at;  // past ';'
    const std::size_t eq = header.find_first_of("=;", at);
    if (eq == std::string_view::npos) return std::nullopt;
    const std::string name = lower(trim(header.substr(at, eq - at)));
    if (header[eq] == ';') {  // a parameter without a value
      at = eq;
      continue;
    }
    std::size_t v = eq + 1;
    while (v < header.size() && header[v] == ' ') ++v;
    std::string value;
    if (v < header.size() && header[v] == '"') {
      for (++v; v < header.size() && header[v] != '"'; ++v) {
        if (header[v] == '\\' && v + 1 < header.size()) ++v;
        value += header[v];
      }
      at = header.find(';', v);
    } else {
      at = header.find(';', v);
      value = std::string(trim(header.substr(v, at == std::string_view::npos ? at : at - v)));
    }
    if (name == key) return value;
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> multipart_boundary(std::string_view content_type) {
  if (lower(content_type).rfind("multipart/form-data", 0) != 0) return std::nullopt;
  auto b = parameter(content_type, "boundary");
  if (!b || b->empty() || b->size() > 200) return std::nullopt;
  return b;
}

std::vector<FormPart> parse_multipart(std::string_view body, std::string_view boundary) {
  const std::string delimiter = "--" + std::string(boundary);
  std::size_t at = body.find(delimiter);
  if (at == std::string_view::npos) throw std::invalid_argument("multipart body without its boundary");
  std::vector<FormPart> parts;
  for (;;) {
    at += delimiter.size();
    if (body.substr(at, 2) == "--") return parts;  // the closing delimiter
    if (body.substr(at, 2) != "\r\n")
      throw std::invalid_argument("multipart boundary not followed by a line end");
    at += 2;
    const std::size_t headers_end = body.find("\r\n\r\n", at);
    if (headers_end == std::string_view::npos)
      throw std::invalid_argument("multipart part without the end of its headers");
    FormPart part;
    part.content_type = "text/plain";
    for (std::string_view headers = body.substr(at, headers_end - at); !headers.empty();) {
      const std::size_t eol = headers.find("\r\n");
      const std::string_view line = headers.substr(0, eol);
      headers = eol == std::string_view::npos ? std::string_view{} : headers.substr(eol + 2);
      const std::size_t colon = line.find(':');
      if (colon == std::string_view::npos) throw std::invalid_argument("malformed multipart header line");
      const std::string name = lower(trim(line.substr(0, colon)));
      const std::string_view value = trim(line.substr(colon + 1));
      if (name == "content-disposition") {
        part.name = parameter(value, "name").value_or("");
        part.filename = parameter(value, "filename");
      } else if (name == "content-type") {
        part.content_type = std::string(value);
      }
    }
    const std::size_t content = headers_end + 4;
    const std::size_t next = body.find("\r\n" + delimiter, content);
    if (next == std::string_view::npos) throw std::invalid_argument("multipart body ends inside a part");
    part.body = std::string(body.substr(content, next - content));
    parts.push_back(std::move(part));
    at = next + 2;
  }
}

}  // namespace salient::server
