// Router: every endpoint declared once, with its method, path pattern ("/api/v1/jobs/{id}"),
// access (open, or an API key) and handler. Handlers throw ApiError (or services a DomainError) for a
// client's mistake; the router turns it, and anything unexpected, into the JSON error body {"error": {code,
// message}}.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "server/common/domain_error.hpp"
#include "server/http/http_message.hpp"

namespace salient::server {

class ApiError : public std::runtime_error {
 public:
  ApiError(int status, std::string code, const std::string& message)
      : std::runtime_error(message), status_(status), code_(std::move(code)) {}
  int status() const { return status_; }
  const std::string& code() const { return code_; }
  ApiError& with_header(std::string name, std::string value) {
    headers_.emplace_back(std::move(name), std::move(value));
    return *this;
  }
  const std::vector<std::pair<std::string, std::string>>& headers() const { return headers_; }

 private:
  int status_;
  std::string code_;
  std::vector<std::pair<std::string, std::string>> headers_;
};

HttpResponse error_response(int status, const std::string& code, const std::string& message);
// The one place a DomainError's kind becomes a status (and Retry-After).
int status_of(ErrorKind kind);
HttpResponse domain_error_response(const DomainError& e);

using PathParams = std::map<std::string, std::string>;
using Handler = std::function<HttpResponse(const HttpRequest&, const PathParams&)>;
enum class Access { open, key };

struct Route {
  std::string method;
  std::string pattern;
  Access access;
  Handler handler;
  std::string name;  // the pattern, for metrics and logs
};

class Router {
 public:
  void add(std::string method, std::string pattern, Access access, Handler handler);
  void set_authenticator(std::function<bool(const HttpRequest&)> check) { authenticate_ = std::move(check); }
  // Turns an exception a handler let through (not an ApiError) into the response: a full disk
  // into 507, say. Without one, or when it returns nothing, it is a 500 that names no detail
  // (which may hold paths); `route` is the matched pattern, for the log.
  using ExceptionMapper =
      std::function<std::optional<HttpResponse>(const std::exception&, const std::string& route)>;
  void set_exception_mapper(ExceptionMapper mapper) { map_exception_ = std::move(mapper); }

  // 404 when no pattern matches, 405 (with Allow) when only the method is wrong, 401 without a
  // valid key on a keyed route. `route_name` gets the matched pattern (or "unmatched").
  HttpResponse dispatch(const HttpRequest& request, std::string* route_name = nullptr) const;
  // The 404, 405 or 401 that `request` gets whatever its body: the server asks this on the
  // headers alone, so that nobody without a key can make it read (and hold) a body.
  std::optional<HttpResponse> refusal(const HttpRequest& request, std::string* route_name = nullptr) const;
  const std::vector<Route>& routes() const { return routes_; }

 private:
  std::vector<Route> routes_;
  std::function<bool(const HttpRequest&)> authenticate_;
  ExceptionMapper map_exception_;
};

// Matches "/api/v1/jobs/{id}" against a path, filling the named segments; a last segment
// "{name*}" takes the rest of the path (one character at least), slashes included.
bool match_pattern(const std::string& pattern, const std::string& path, PathParams& params);

}  // namespace salient::server
