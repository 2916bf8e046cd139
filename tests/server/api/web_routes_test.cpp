// The web page's routes through the router, as the server dispatches them (the target decoded
// as http_session does): the page from the binary with its CSP, ETag and 304; the libraries from
// a vendor directory; and nothing outside that directory, however the path is spelled.
#include <doctest/doctest.h>

#include <fstream>
#include <regex>
#include <set>

#include "server/api/routes.hpp"
#include "server/api/web_assets.hpp"
#include "tests/support/scratch_dir.hpp"

using namespace salient::server;
namespace fs = std::filesystem;

namespace {

void write_file(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

struct Page {
  salient::test::ScratchDir dir{"web-routes"};
  Router router;
  explicit Page(bool with_vendor = true) {
    if (with_vendor) {
      write_file(dir.path / "js/three/three.module.js", "export const REVISION = '111';\n");
      write_file(dir.path / "js/chart.js/chunks/helpers.segment.js", "export const h = 1;\n");
      write_file(dir.path / "js/secret.js", "SECRET\n");  // beside the libraries, not in one
      write_file(dir.path / "js/three/notes.txt", "not a module\n");
      fs::create_symlink("../secret.js", dir.path / "js/three/escape.js");
      fs::create_symlink("three.module.js", dir.path / "js/three/alias.js");
    }
    DaemonConfig config;
    config.web_vendor_dir = (dir.path / "js").string();
    router.set_authenticator(
        [](const HttpRequest&) { return std::optional<Principal>(); });  // no key: the page is open
    add_web_routes(router, config);
  }
  HttpResponse get(const std::string& target, const std::string& if_none_match = "") const {
    HttpRequest r;
    r.method = "GET";
    r.target = target;
    REQUIRE(split_target(target, r.path, r.query));
    r.headers["host"] = "127.0.0.1:8080";
    if (!if_none_match.empty()) r.headers["if-none-match"] = if_none_match;
    return router.dispatch(r);
  }
};

std::string header(const HttpResponse& r, const std::string& name) {
  for (const auto& [n, v] : r.headers)
    if (n == name) return v;
  return {};
}

std::string asset(const std::string& name) {
  for (const WebAsset& a : web_assets())
    if (a.name == name) return std::string(a.bytes);
  return {};
}

}  // namespace

TEST_CASE("the page is served from the binary with its content type, a CSP and no key") {
  Page page;
  const HttpResponse index = page.get("/");
  REQUIRE(index.status == 200);
  CHECK(index.content_type == "text/html; charset=utf-8");
  CHECK(index.body == asset("index.html"));
  CHECK(index.body.find("<html") != std::string::npos);
  const std::string csp = header(index, "Content-Security-Policy");
  CHECK(csp.find("default-src 'self'") != std::string::npos);
  CHECK(csp.find("script-src 'self';") != std::string::npos);  // no inline script, no other origin
  CHECK(csp.find("unsafe") == std::string::npos);
  CHECK(csp.find("http") == std::string::npos);
  CHECK(csp.find("connect-src 'self' ws://127.0.0.1:8080 wss://127.0.0.1:8080;") != std::string::npos);
  CHECK(header(index, "X-Content-Type-Options") == "nosniff");
  CHECK(header(index, "Cache-Control") == "no-cache");
  CHECK(page.get("/web/index.html").body == index.body);
  for (const WebAsset& a : web_assets()) {
    const HttpResponse r = page.get("/web/" + std::string(a.name));
    CHECK(r.status == 200);
    if (a.name.ends_with(".js")) CHECK(r.content_type == "text/javascript; charset=utf-8");
    if (a.name.ends_with(".css")) CHECK(r.content_type == "text/css; charset=utf-8");
  }
  const HttpResponse missing = page.get("/web/nothing.js");
  CHECK(missing.status == 404);
  CHECK(missing.body.find("the web page has no file 'nothing.js'") != std::string::npos);
}

TEST_CASE("an ETag, and 304 without a body when the browser has it") {
  Page page;
  const HttpResponse first = page.get("/");
  const std::string etag = header(first, "ETag");
  REQUIRE(etag.size() > 2);
  CHECK(etag.front() == '"');
  const HttpResponse again = page.get("/", etag);
  CHECK(again.status == 304);
  CHECK(again.body.empty());
  CHECK(header(again, "ETag") == etag);
  CHECK(page.get("/", "\"other\", W/" + etag).status == 304);
  CHECK(page.get("/", "*").status == 304);
  CHECK(page.get("/", "\"other\"").status == 200);
  // Each file has its own tag.
  CHECK(header(page.get("/web/style.css"), "ETag") != etag);
}

TEST_CASE("the libraries come from the vendor directory, with an ETag and a cache time") {
  Page page;
  const HttpResponse three = page.get("/vendor/three/three.module.js");
  REQUIRE(three.status == 200);
  CHECK(three.body == "export const REVISION = '111';\n");
  CHECK(three.content_type == "text/javascript; charset=utf-8");
  CHECK(header(three, "Cache-Control") == "public, max-age=3600");
  CHECK(!header(three, "Content-Security-Policy").empty());
  CHECK(page.get("/vendor/three/three.module.js", header(three, "ETag")).status == 304);
  CHECK(page.get("/vendor/chart.js/chunks/helpers.segment.js").body == "export const h = 1;\n");
  CHECK(page.get("/vendor/three/alias.js").body == three.body);  // a link inside the package
  CHECK(page.get("/vendor/three/missing.js").status == 404);
  CHECK(page.get("/vendor/three/notes.txt").status == 404);  // modules only
  CHECK(page.get("/vendor/jquery/jquery.js").status == 404);
}

TEST_CASE("no path reaches a file outside the library's directory") {
  Page page;
  for (const char* target :
       {"/vendor/three/../secret.js", "/vendor/three/..%2Fsecret.js", "/vendor/three/%2e%2e/secret.js",
        "/vendor/three/%2E%2E%2Fsecret.js", "/vendor/three/.%2e/secret.js", "/vendor/%2e%2e/secret.js",
        "/vendor/three/escape.js", "/vendor/three//etc/passwd", "/vendor/three/%2Fetc%2Fpasswd",
        "/vendor/three/%2F%2E%2E%2Fsecret.js", "/vendor/chart.js/chunks/..%2F..%2Fsecret.js",
        "/vendor/three/three.module.js%00.js", "/vendor/three/%2e%2e%5csecret.js", "/web/..%2Fweb_routes.cpp",
        "/vendor/.%2Fthree/three.module.js", "/vendor/three/.hidden.js"}) {
    CAPTURE(target);
    const HttpResponse r = page.get(target);
    CHECK(r.status >= 400);
    CHECK(r.status < 500);
    CHECK(r.body.find("SECRET") == std::string::npos);
  }
}

TEST_CASE("a missing library is a 404 that says which package to install") {
  Page page(false);
  const HttpResponse r = page.get("/vendor/three/three.module.js");
  CHECK(r.status == 404);
  CHECK(r.body.find("not_installed") != std::string::npos);
  CHECK(r.body.find("libjs-three") != std::string::npos);
  CHECK(page.get("/vendor/chart.js/chart.esm.js").body.find("libjs-chart.js") != std::string::npos);
  CHECK(page.get("/").status == 200);  // the page itself still loads, and says what is missing
}

TEST_CASE("every file the page names is compiled in, and it names nothing outside this server") {
  std::set<std::string> names;
  for (const WebAsset& a : web_assets()) names.insert(std::string(a.name));
  REQUIRE(names.count("index.html") == 1);
  REQUIRE(names.count("app.js") == 1);
  // "/web/x", './x.js' (imports), "/vendor/…": what the HTML and the modules load.
  const std::regex local(R"re((?:/web/|['"]\./)([\w.-]+\.(?:js|css|svg)))re");
  const std::regex vendor(R"re(['"](/vendor/[\w./-]+))re");
  const std::regex outside(R"re((?:src|href|from|import\()\s*=?\s*['"](?:https?:)?//)re");
  Page page;
  int referenced = 0;
  for (const WebAsset& a : web_assets()) {
    const std::string text(a.bytes);
    CAPTURE(a.name);
    for (auto m = std::sregex_iterator(text.begin(), text.end(), local); m != std::sregex_iterator(); ++m) {
      CAPTURE((*m)[1].str());
      CHECK(names.count((*m)[1].str()) == 1);
      ++referenced;
    }
    for (auto m = std::sregex_iterator(text.begin(), text.end(), vendor); m != std::sregex_iterator(); ++m) {
      const std::string path = (*m)[1].str();
      CAPTURE(path);
      CHECK((path == "/vendor/three/three.module.js" || path == "/vendor/chart.js/chart.esm.js"));
    }
    CHECK(!std::regex_search(text, outside));           // no CDN, no other origin
    CHECK(text.find("<script>") == std::string::npos);  // no inline script (the CSP would refuse it)
    CHECK(text.find(" style=") == std::string::npos);   // nor inline style
  }
  CHECK(referenced > 10);
}
