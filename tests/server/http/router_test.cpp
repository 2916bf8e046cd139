#include "server/http/router.hpp"

#include <doctest/doctest.h>

using namespace salient::server;

namespace {
HttpRequest request(std::string method, std::string path) {
  HttpRequest r;
  r.method = std::move(method);
  r.path = std::move(path);
  return r;
}
}  // namespace

TEST_CASE("patterns fill named segments and match whole paths only") {
  PathParams p;
  CHECK(match_pattern("/api/v1/jobs/{id}", "/api/v1/jobs/j42", p));
  CHECK(p.at("id") == "j42");
  CHECK(match_pattern("/api/v1/jobs/{id}/gcode", "/api/v1/jobs/j42/gcode", p));
  CHECK_FALSE(match_pattern("/api/v1/jobs/{id}", "/api/v1/jobs/j42/gcode", p));
  CHECK_FALSE(match_pattern("/api/v1/jobs/{id}", "/api/v1/jobs/", p));
  CHECK_FALSE(match_pattern("/api/v1/jobs", "/api/v1/jobsx", p));
}

TEST_CASE("dispatch: handlers, 404, 405 with Allow, 401, ApiError and unexpected errors as JSON") {
  Router router;
  router.add("GET", "/healthz", Access::open,
             [](const HttpRequest&, const PathParams&) { return HttpResponse::text(200, "ok"); });
  router.add("GET", "/api/v1/jobs/{id}", Access::key,
             [](const HttpRequest&, const PathParams& p) -> HttpResponse {
               if (p.at("id") == "missing") throw ApiError(404, "not_found", "no job missing");
               if (p.at("id") == "boom") throw std::runtime_error("disk on fire");
               return HttpResponse::text(200, p.at("id"));
             });
  router.add("DELETE", "/api/v1/jobs/{id}", Access::key,
             [](const HttpRequest&, const PathParams&) { return HttpResponse::text(204, ""); });
  router.set_authenticator([](const HttpRequest& r) { return r.header("x-api-key") == "k"; });

  std::string route;
  CHECK(router.dispatch(request("GET", "/healthz"), &route).body == "ok");
  CHECK(route == "/healthz");
  HttpRequest keyed = request("GET", "/api/v1/jobs/j1");
  CHECK(router.dispatch(keyed).status == 401);
  CHECK(router.dispatch(keyed).body.find("\"code\":\"unauthorized\"") != std::string::npos);
  keyed.headers["x-api-key"] = "k";
  CHECK(router.dispatch(keyed).body == "j1");
  keyed.path = "/api/v1/jobs/missing";
  const HttpResponse missing = router.dispatch(keyed);
  CHECK(missing.status == 404);
  CHECK(missing.body == R"({"error":{"code":"not_found","message":"no job missing"}})");
  keyed.path = "/api/v1/jobs/boom";
  CHECK(router.dispatch(keyed).status == 500);
  const HttpResponse wrong = router.dispatch(request("PUT", "/api/v1/jobs/j1"));
  CHECK(wrong.status == 405);
  REQUIRE(wrong.headers.size() == 1);
  CHECK(wrong.headers[0].second == "GET, DELETE");
  CHECK(router.dispatch(request("GET", "/nowhere"), &route).status == 404);
  CHECK(route == "unmatched");
}

TEST_CASE("targets: percent-decoding and query parameters") {
  std::string path;
  std::map<std::string, std::string> query;
  CHECK(split_target("/api/v1/jobs?state=done&limit=5&name=my%20part+2&flag", path, query));
  CHECK(path == "/api/v1/jobs");
  CHECK(query.at("state") == "done");
  CHECK(query.at("name") == "my part 2");
  CHECK(query.at("flag").empty());
  CHECK(split_target("/a%2Fb", path, query));
  CHECK(path == "/a/b");
  CHECK_FALSE(split_target("/bad%zz", path, query));
  CHECK_FALSE(split_target("/bad%2", path, query));
}

TEST_CASE("HEAD is served wherever GET is, and only there") {
  Router router;
  router.add("GET", "/", Access::open,
             [](const HttpRequest&, const PathParams&) { return HttpResponse::text(200, "page"); });
  router.add("POST", "/api/v1/jobs", Access::key,
             [](const HttpRequest&, const PathParams&) { return HttpResponse::text(201, "made"); });
  std::string route;
  const HttpResponse head = router.dispatch(request("HEAD", "/"), &route);
  CHECK(head.status == 200);  // the session writes its headers and Content-Length, not its body
  CHECK(route == "/");
  const HttpResponse post = router.dispatch(request("HEAD", "/api/v1/jobs"));
  CHECK(post.status == 405);
  REQUIRE(post.headers.size() == 1);
  CHECK(post.headers[0].second == "POST");
}
