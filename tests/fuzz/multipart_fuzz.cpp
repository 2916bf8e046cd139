// Fuzz target for multipart/form-data: the first line is the Content-Type header, the rest the
// body. Only std::invalid_argument may come out, and every part must be a piece of the body
// that holds no delimiter.
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>

#include "server/http/multipart.hpp"

using namespace salient::server;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  const std::size_t eol = all.find('\n');
  std::string_view type = all.substr(0, eol);
  if (!type.empty() && type.back() == '\r') type.remove_suffix(1);
  const std::string_view body = eol == std::string_view::npos ? std::string_view{} : all.substr(eol + 1);
  const auto boundary = multipart_boundary(type);
  if (!boundary) return 0;
  if (boundary->empty() || boundary->size() > 200) std::abort();
  const std::string delimiter = "\r\n--" + *boundary;
  try {
    const auto parts = parse_multipart(body, *boundary);
    if (parts.size() > body.size() / (delimiter.size() - 2)) std::abort();  // each part costs a delimiter
    for (const FormPart& p : parts) {
      if (p.body.size() > body.size() || body.find(p.body) == std::string_view::npos) std::abort();
      if (p.body.find(delimiter) != std::string::npos) std::abort();  // the part ran past its end
    }
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
