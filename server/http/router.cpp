#include "server/http/router.hpp"

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

std::optional<HttpResponse> Router::refusal(const HttpRequest& request, std::string* route_name) const {
  std::string allowed;
  PathParams params;
  for (const Route& route : routes_) {
    if (!match_pattern(route.pattern, request.path, params)) continue;
    if (!serves(route, request.method)) {
      allowed += (allowed.empty() ? "" : ", ") + route.method;
      continue;
    }
    if (route_name) *route_name = route.name;
    if (route.access == Access::key && authenticate_ && !authenticate_(request))
      return error_response(401, "unauthorized",
                            "an API key is required: X-Api-Key: KEY or Authorization: Bearer KEY");
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

HttpResponse Router::dispatch(const HttpRequest& request, std::string* route_name) const {
  if (auto refused = refusal(request, route_name)) return *refused;
  PathParams params;
  for (const Route& route : routes_) {
    if (!serves(route, request.method) || !match_pattern(route.pattern, request.path, params)) continue;
    try {
      return route.handler(request, params);
    } catch (const ApiError& e) {
      HttpResponse r = error_response(e.status(), e.code(), e.what());
      r.headers.insert(r.headers.end(), e.headers().begin(), e.headers().end());
      return r;
    } catch (const DomainError& e) {
      return domain_error_response(e);
    } catch (const std::exception& e) {
      if (map_exception_)
        if (auto r = map_exception_(e, route.name)) return *r;
      return error_response(500, "internal", "internal error (logged)");
    }
  }
  return error_response(404, "not_found", "no such endpoint: " + request.path.substr(0, 256));
}

}  // namespace salient::server
