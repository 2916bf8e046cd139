// HttpRequest / HttpResponse: what a route handler sees and returns: plain strings, so that no
// Beast type leaves http_server.cpp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "server/http/principal.hpp"

namespace salient::server {

struct HttpRequest {
  std::string method;                          // "GET", "POST", …
  std::string target;                          // as sent: path and query
  std::string path;                            // percent-decoded, without the query
  std::map<std::string, std::string> query;    // decoded
  std::map<std::string, std::string> headers;  // names in lower case
  std::string body;
  std::string
      remote;  // the client's address: the peer's, or a trusted proxy's X-Forwarded-For (client_address.hpp)
  // The URL the client used, where a trusted proxy says so: its scheme, and the path prefix the
  // proxy serves salientd under ("" at the root; [server] base_path otherwise). The "host" header
  // is the proxy's X-Forwarded-Host when it sent one.
  std::string scheme = "http";
  std::string base_path;
  // Who called: set by the router on a keyed route once the key is checked; empty on open routes.
  std::optional<Principal> caller;

  // The header's value, or "" when absent (`name` in lower case).
  std::string header(std::string_view name) const;
};

struct HttpResponse {
  // A body read from a file as the client takes it, instead of `body`: `length` bytes from
  // `offset`. The server holds one chunk per connection, never the file: downloads of large
  // G-code by slow (or stalled) clients stay within a bounded memory.
  struct FileRange {
    std::filesystem::path path;
    std::uint64_t offset = 0, length = 0;
  };

  int status = 200;
  std::string content_type = "application/json";
  std::string body;
  std::optional<FileRange> file;
  std::vector<std::pair<std::string, std::string>> headers;

  static HttpResponse text(int status, std::string body,
                           std::string content_type = "text/plain; charset=utf-8");
  static HttpResponse from_file(int status, FileRange file, std::string content_type);
};

// Splits "/a%20b?x=1&y" into its decoded path and query parameters; false when the
// percent-encoding is malformed.
bool split_target(std::string_view target, std::string& path, std::map<std::string, std::string>& query);

}  // namespace salient::server
