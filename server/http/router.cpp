#include "server/http/router.hpp"

#include <charconv>
#include <nlohmann/json.hpp>

#include "server/common/json_text.hpp"

namespace salient::server {

HttpResponse error_response(int status, const std::string& code, const std::string& message) {
  HttpResponse r;
  r.status = status;
  r.body = json_text(nlohmann::json{{"error", {{"code", code}, {"message", message}}}});
  return r;
}

int status_of(ErrorKind kind) {
  switch (kind) {
    case ErrorKind::bad_request:
      return 400;
    case ErrorKind::not_found:
      return 404;
    case ErrorKind::conflict:
      return 409;
    case ErrorKind::unsupported:
      return 415;
    case ErrorKind::unprocessable:
      return 422;
    case ErrorKind::too_busy:
      return 429;
  }
  return 500;
}

HttpResponse domain_error_response(const DomainError& e) {
  HttpResponse r = error_response(status_of(e.kind()), e.code(), e.what());
  if (e.retry_after()) r.headers.emplace_back("Retry-After", std::to_string(*e.retry_after()));
  return r;
}

void Router::add(std::string method, std::string pattern, Access access, Handler handler) {
  std::string name = pattern;
  routes_.push_back({std::move(method), std::move(pattern), access, std::move(handler), std::move(name)});
}

namespace {
// HEAD is GET without the body (RFC 9110 §9.3.2): the session leaves the body out.
bool serves(const Route& route, const std::string& method) {
  return route.method == method || (method == "HEAD" && route.method == "GET");
}
}  // namespace

bool match_pattern(const std::string& pattern, const std::string& path, PathParams& params) {
  params.clear();
  std::size_t p = 0, s = 0;
  while (p < pattern.size() && s < path.size()) {
    if (pattern[p] == '{') {
      const std::size_t close = pattern.find('}', p);
      // "{name*}" as the pattern's last segment takes the rest of the path, slashes and all.
      if (close + 1 == pattern.size() && close > p + 1 && pattern[close - 1] == '*') {
        params[pattern.substr(p + 1, close - p - 2)] = path.substr(s);
        return true;
      }
      const std::size_t end = path.find('/', s);
      const std::string value = path.substr(s, end == std::string::npos ? std::string::npos : end - s);
      if (value.empty()) return false;
      params[pattern.substr(p + 1, close - p - 1)] = value;
      p = close + 1;
      s = end == std::string::npos ? path.size() : end;
      continue;
    }
    if (pattern[p] != path[s]) return false;
    ++p, ++s;
  }
  return p == pattern.size() && s == path.size();
}

std::optional<Role> needed_role(Access access, const std::string& method) {
  switch (access) {
    case Access::open:
      return std::nullopt;
    case Access::key:
      return method == "GET" || method == "HEAD" ? Role::viewer : Role::operator_;
    case Access::viewer:
      return Role::viewer;
    case Access::operator_:
      return Role::operator_;
    case Access::admin:
      return Role::admin;
  }
  return Role::admin;
}

bool octoprint_path(const std::string& path) {
  const auto under = [&](std::string_view prefix) { return path.rfind(prefix, 0) == 0; };
  if (under("/api/v1/") || path == "/api/v1") return false;
  return under("/api/") || under("/plugin/") || under("/downloads/");
}

namespace {

// Whether the request carried a key at all (where ApiKeys::authenticate looks for one).
bool presents_key(const HttpRequest& request) {
  return !request.header("x-api-key").empty() || request.header("authorization").rfind("Bearer ", 0) == 0 ||
         request.query.count("apikey") > 0;
}

// No key and a wrong key are told apart: a person who typed a key should not read that one is
// required, but that this one is not known.
HttpResponse unauthenticated(const HttpRequest& request) {
  const bool presented = presents_key(request);
  if (octoprint_path(request.path))
    return error_response(403, "forbidden",
                          presented ? "this API key is not one salientd knows (mistyped, or revoked)"
                                    : "a valid API key is required: X-Api-Key: KEY");
  HttpResponse r = error_response(
      401, "unauthorized",
      presented ? "this API key is not one salientd knows (mistyped, or revoked): check it against the "
                  "api-key file in salientd's data directory, or ask its admin for a key"
                : "an API key is required: X-Api-Key: KEY or Authorization: Bearer KEY");
  r.headers.emplace_back("WWW-Authenticate", "Bearer realm=\"salient\"");
  return r;
}

// An open route's body, judged on the headers: a declared length within kOpenBodyLimit.
std::optional<HttpResponse> open_body_refusal(const HttpRequest& request) {
  const std::string length = request.header("content-length");
  if (length.empty()) {
    if (request.header("transfer-encoding").empty()) return std::nullopt;
    return error_response(411, "length_required", "send this request with a Content-Length");
  }
  std::size_t n = 0;
  const auto [end, ec] = std::from_chars(length.data(), length.data() + length.size(), n);
  if (ec != std::errc() || end != length.data() + length.size() || n > kOpenBodyLimit)
    return error_response(
        413, "too_large",
        "a request without an API key may carry at most " + std::to_string(kOpenBodyLimit) + " bytes");
  return std::nullopt;
}

}  // namespace

std::optional<HttpResponse> Router::check(const HttpRequest& request, std::string* route_name,
                                          const Route** matched, std::optional<Principal>* caller) const {
  std::string allowed;
  PathParams params;
  for (const Route& route : routes_) {
    if (!match_pattern(route.pattern, request.path, params)) continue;
    if (!serves(route, request.method)) {
      allowed += (allowed.empty() ? "" : ", ") + route.method;
      continue;
    }
    if (route_name) *route_name = route.name;
    if (matched) *matched = &route;
    const std::optional<Role> needed = needed_role(route.access, request.method);
    if (!needed) return open_body_refusal(request);
    if (!authenticate_) return std::nullopt;
    std::optional<Principal> who = authenticate_(request);
    if (!who) return unauthenticated(request);
    if (who->role < *needed)
      return error_response(403, "forbidden",
                            "the key of '" + who->user + "' (" + std::string(to_string(who->role)) +
                                ") may not do this: it needs the role " + std::string(to_string(*needed)));
    if (caller) *caller = std::move(who);
    return std::nullopt;
  }
  if (route_name) *route_name = "unmatched";
  if (!allowed.empty()) {
    // Outside text in the message is cut short: a method may be 10 KB of anything.
    HttpResponse r =
        error_response(405, "method_not_allowed",
                       request.method.substr(0, 32) + " is not allowed on " + request.path.substr(0, 256));
    r.headers.emplace_back("Allow", allowed);
    return r;
  }
  return error_response(404, "not_found", "no such endpoint: " + request.path.substr(0, 256));
}

std::optional<HttpResponse> Router::refusal(const HttpRequest& request, std::string* route_name) const {
  return check(request, route_name, nullptr, nullptr);
}

HttpResponse Router::dispatch(HttpRequest& request, std::string* route_name) const {
  const Route* route = nullptr;
  std::optional<Principal> caller;
  // The key is checked again with the body read: it may have been revoked in between.
  if (auto refused = check(request, route_name, &route, &caller)) return *refused;
  request.caller = std::move(caller);
  PathParams params;
  match_pattern(route->pattern, request.path, params);
  try {
    return route->handler(request, params);
  } catch (const ApiError& e) {
    HttpResponse r = error_response(e.status(), e.code(), e.what());
    r.headers.insert(r.headers.end(), e.headers().begin(), e.headers().end());
    return r;
  } catch (const DomainError& e) {
    return domain_error_response(e);
  } catch (const std::exception& e) {
    if (map_exception_)
      if (auto r = map_exception_(e, route->name)) return *r;
    return error_response(500, "internal", "internal error (logged)");
  }
}

}  // namespace salient::server
