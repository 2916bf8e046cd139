#include "server/http/router.hpp"

#include <doctest/doctest.h>

using namespace salient::server;

namespace {
HttpRequest request(std::string method, std::string path, std::string key = "") {
  HttpRequest r;
  r.method = std::move(method);
  r.path = std::move(path);
  if (!key.empty()) r.headers["x-api-key"] = std::move(key);
  return r;
}

// Keys "v", "o" and "a": a viewer, an operator and an admin.
std::optional<Principal> by_key(const HttpRequest& r) {
  const std::string key = r.header("x-api-key");
  if (key == "v") return Principal{"vic", Role::viewer, 1};
  if (key == "o") return Principal{"otto", Role::operator_, 2};
  if (key == "a") return Principal{"ada", Role::admin, 3};
  return std::nullopt;
}

HttpResponse who(const HttpRequest& r, const PathParams&) {
  return HttpResponse::text(200, r.caller ? r.caller->user : "nobody");
}

std::string header(const HttpResponse& r, const std::string& name) {
  for (const auto& [n, v] : r.headers)
    if (n == name) return v;
  return "";
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
  router.set_authenticator([](const HttpRequest& r) -> std::optional<Principal> {
    if (r.header("x-api-key") != "k") return std::nullopt;
    return Principal{"tester", Role::admin};
  });

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

TEST_CASE("roles: reading needs a viewer, acting an operator, explicit levels override the method") {
  Router router;
  router.add("GET", "/api/v1/printers", Access::key, who);
  router.add("POST", "/api/v1/printers/{id}/print", Access::key, who);
  router.add("POST", "/api/v1/keys", Access::admin, who);
  router.add("POST", "/api/login", Access::viewer, who);
  router.set_authenticator(by_key);

  CHECK(router.dispatch(request("GET", "/api/v1/printers", "v")).body == "vic");
  CHECK(router.dispatch(request("HEAD", "/api/v1/printers", "v")).status == 200);
  const HttpResponse viewer_prints = router.dispatch(request("POST", "/api/v1/printers/sim/print", "v"));
  CHECK(viewer_prints.status == 403);
  CHECK(viewer_prints.body.find("\"code\":\"forbidden\"") != std::string::npos);
  CHECK(viewer_prints.body.find("operator") != std::string::npos);  // says which role it needs
  CHECK(router.dispatch(request("POST", "/api/v1/printers/sim/print", "o")).body == "otto");
  CHECK(router.dispatch(request("POST", "/api/v1/keys", "o")).status == 403);
  CHECK(router.dispatch(request("POST", "/api/v1/keys", "a")).body == "ada");
  // A POST that only reads: a viewer may, and the handler sees who called.
  CHECK(router.dispatch(request("POST", "/api/login", "v")).body == "vic");
  // The role is judged on the headers alone, before any body is read.
  const auto early = router.refusal(request("POST", "/api/v1/printers/sim/print", "v"));
  REQUIRE(early);
  CHECK(early->status == 403);
  CHECK_FALSE(router.refusal(request("POST", "/api/v1/printers/sim/print", "o")));
}

TEST_CASE("without a valid key: 401 with WWW-Authenticate on ours, 403 on OctoPrint's paths") {
  Router router;
  for (const char* path : {"/api/v1/jobs", "/api/job", "/api/files/local/{name}",
                           "/plugin/appkeys/decision/{t}", "/downloads/files/local/{name}", "/metrics"})
    router.add("GET", path, Access::key, who);
  router.set_authenticator(by_key);
  std::vector<std::string> keys_tried = {"", "wrong", std::string(10000, 'k')};
  keys_tried.push_back(std::string("v") + '\0' + "x");  // a valid key with a NUL and more after it
  for (const std::string& key : keys_tried) {
    const HttpResponse ours = router.dispatch(request("GET", "/api/v1/jobs", key));
    CHECK(ours.status == 401);
    CHECK(header(ours, "WWW-Authenticate").rfind("Bearer", 0) == 0);
    CHECK(router.dispatch(request("GET", "/metrics", key)).status == 401);
    for (const char* path : {"/api/job", "/api/files/local/a.gcode", "/plugin/appkeys/decision/t",
                             "/downloads/files/local/a.gcode"}) {
      const HttpResponse theirs = router.dispatch(request("GET", path, key));
      CHECK_MESSAGE(theirs.status == 403, path);
      CHECK(header(theirs, "WWW-Authenticate").empty());
    }
  }
  CHECK(octoprint_path("/api/job"));
  CHECK(octoprint_path("/api/login"));
  CHECK_FALSE(octoprint_path("/api/v1/jobs"));
  CHECK_FALSE(octoprint_path("/api/v1"));
  CHECK(octoprint_path("/api/v1x"));
  CHECK_FALSE(octoprint_path("/healthz"));
}

TEST_CASE("an open route reads at most a small body of declared length, refused on the headers") {
  Router router;
  router.add("POST", "/plugin/appkeys/request", Access::open, who);
  HttpRequest small = request("POST", "/plugin/appkeys/request");
  small.headers["content-length"] = "100";
  CHECK_FALSE(router.refusal(small));
  CHECK(router.dispatch(small).body == "nobody");  // open: no caller
  HttpRequest big = small;
  big.headers["content-length"] = std::to_string(kOpenBodyLimit + 1);
  REQUIRE(router.refusal(big));
  CHECK(router.refusal(big)->status == 413);
  big.headers["content-length"] = "99999999999999999999999";
  CHECK(router.refusal(big)->status == 413);
  HttpRequest chunked = request("POST", "/plugin/appkeys/request");
  chunked.headers["transfer-encoding"] = "chunked";
  REQUIRE(router.refusal(chunked));
  CHECK(router.refusal(chunked)->status == 411);
}

TEST_CASE("needed roles by access and method") {
  CHECK_FALSE(needed_role(Access::open, "POST"));
  CHECK(needed_role(Access::key, "GET") == Role::viewer);
  CHECK(needed_role(Access::key, "HEAD") == Role::viewer);
  CHECK(needed_role(Access::key, "POST") == Role::operator_);
  CHECK(needed_role(Access::key, "DELETE") == Role::operator_);
  CHECK(needed_role(Access::viewer, "POST") == Role::viewer);
  CHECK(needed_role(Access::admin, "GET") == Role::admin);
  CHECK(role_from("operator") == Role::operator_);
  CHECK_FALSE(role_from("root"));
  CHECK_FALSE(role_from("Admin"));
}
