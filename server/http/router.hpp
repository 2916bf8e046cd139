// Router: every endpoint declared once, with its method, path pattern ("/api/v1/jobs/{id}"),
// access (open, or an API key and the role it needs) and handler. Handlers throw ApiError (or services a
// DomainError) for a client's mistake; the router turns it, and anything unexpected, into the JSON error body
// {"error": {code, message}}.
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
// key: any key whose role suffices for the method — GET and HEAD read (viewer), anything else
// acts (operator). viewer/operator_/admin: that role whatever the method (a POST that only reads
// such as OctoPrint's passive login; key management).
enum class Access { open, key, viewer, operator_, admin };
// The role a route needs from its caller; nothing for an open route.
std::optional<Role> needed_role(Access access, const std::string& method);
// OctoPrint's own paths (/api/… other than /api/v1, /plugin/…, /downloads/…) answer 403 where
// ours answer 401: OctoPrint does, and its clients (FDM Monster) read 403 as "wrong key".
bool octoprint_path(const std::string& path);
// The most body an open route reads (a client without a key may send no more).
inline constexpr std::size_t kOpenBodyLimit = 4096;

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
  // The caller of a request, from its key; nothing when it has none or a wrong one. Without an
  // authenticator every keyed route is served (tests of the rest).
  using Authenticator = std::function<std::optional<Principal>(const HttpRequest&)>;
  void set_authenticator(Authenticator check) { authenticate_ = std::move(check); }
  // Turns an exception a handler let through (not an ApiError) into the response: a full disk
  // into 507, say. Without one, or when it returns nothing, it is a 500 that names no detail
  // (which may hold paths); `route` is the matched pattern, for the log.
  using ExceptionMapper =
      std::function<std::optional<HttpResponse>(const std::exception&, const std::string& route)>;
  void set_exception_mapper(ExceptionMapper mapper) { map_exception_ = std::move(mapper); }

  // 404 when no pattern matches, 405 (with Allow) when only the method is wrong; on a keyed route
  // 401 (ours, with WWW-Authenticate) or 403 (OctoPrint's paths) without a valid key, and 403
  // with a key whose role is too low. Sets request.caller for the handler. `route_name` gets the
  // matched pattern (or "unmatched").
  HttpResponse dispatch(HttpRequest& request, std::string* route_name = nullptr) const;
  HttpResponse dispatch(HttpRequest&& request, std::string* route_name = nullptr) const {
    return dispatch(request, route_name);
  }
  // The 404, 405, 401, 403, 411 or 413 that `request` gets whatever its body: the server asks
  // this on the headers alone, so that nobody without a key can make it read (and hold) a body
  // — an open route reads at most kOpenBodyLimit bytes, of a declared length.
  std::optional<HttpResponse> refusal(const HttpRequest& request, std::string* route_name = nullptr) const;
  const std::vector<Route>& routes() const { return routes_; }

 private:
  // The refusal, else the matched route and (on a keyed route) its caller.
  std::optional<HttpResponse> check(const HttpRequest& request, std::string* route_name, const Route** route,
                                    std::optional<Principal>* caller) const;
  std::vector<Route> routes_;
  Authenticator authenticate_;
  ExceptionMapper map_exception_;
};

// Matches "/api/v1/jobs/{id}" against a path, filling the named segments; a last segment
// "{name*}" takes the rest of the path (one character at least), slashes included.
bool match_pattern(const std::string& pattern, const std::string& path, PathParams& params);

}  // namespace salient::server
