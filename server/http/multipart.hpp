// multipart/form-data bodies (RFC 7578), as curl -F, PrusaSlicer and Cura send them.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace salient::server {

struct FormPart {
  std::string name;
  std::optional<std::string> filename;
  std::string content_type;
  std::string body;
};

// The boundary from a Content-Type header ("multipart/form-data; boundary=…"), if any.
std::optional<std::string> multipart_boundary(std::string_view content_type);

// Splits `body`; throws std::invalid_argument saying what is malformed.
std::vector<FormPart> parse_multipart(std::string_view body, std::string_view boundary);

}  // namespace salient::server
