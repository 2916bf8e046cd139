// The pure parts of OctoPrint's file area: path checking (hostile input), Range parsing (RFC 9110
// cases and huge numbers), the folder tree of a listing, and the router's "{path*}" capture.
#include "server/api/octoprint_files.hpp"

#include <doctest/doctest.h>

#include "server/http/router.hpp"

using namespace salient::server;
using nlohmann::json;

namespace {
int path_status(const std::string& raw, bool root_ok = false) {
  try {
    checked_path(raw, "path", root_ok);
    return 200;
  } catch (const ApiError& e) {
    CHECK(std::string(e.what()).find("'path'") != std::string::npos);
    return e.status();
  }
}
}  // namespace

TEST_CASE(
    "paths: relative and sanitized, with '..', absolute, empty segments, control bytes, bounds refused") {
  CHECK(checked_path("a/b/c.gcode", "path", false) == "a/b/c.gcode");
  CHECK(checked_path("my folder/x y.gcode", "path", false) == "my_folder/x_y.gcode");
  CHECK(checked_path("parts/", "path", false) == "parts");
  CHECK(checked_path("", "path", true).empty());
  CHECK(checked_path("/", "path", true).empty());
  CHECK(path_status("") == 400);
  for (const char* bad : {"..", "../x", "a/../b", "a/..", "./a", "a/./b", "/etc/passwd", "a//b", "//", "a\\b",
                          "a/\x01", "a\x7f"})
    CHECK_MESSAGE(path_status(bad, true) == 400, bad);
  std::string deep;
  for (int i = 0; i < 16; ++i) deep += "d/";
  CHECK(path_status(deep + "x.gcode") == 400);                 // 17 levels
  CHECK(path_status(deep.substr(0, deep.size() - 1)) == 200);  // 16
  CHECK(path_status(std::string(256, 'x')) == 400);
  CHECK(path_status(std::string(255, 'x')) == 200);
  CHECK(path_status(std::string(2000, 'x')) == 400);
  CHECK(in_folder("a", "a/b.gcode"));
  CHECK(in_folder("a", "a"));
  CHECK(in_folder("", "x"));
  CHECK_FALSE(in_folder("a", "ab/c"));
  CHECK(parent_path("a/b/c") == "a/b");
  CHECK(leaf_name("a/b/c") == "c");
  CHECK(join_path("", "x") == "x");
}

TEST_CASE("Range: one range honoured, unsatisfiable ones refused, the rest ignored") {
  using K = RangeAnswer::Kind;
  const auto r = [](const char* h, std::size_t size = 100) { return parse_range(h, size); };
  CHECK(r("").kind == K::whole);
  CHECK(r("bytes=0-9").kind == K::partial);
  CHECK(r("bytes=0-9").first == 0);
  CHECK(r("bytes=0-9").last == 9);
  CHECK(r("BYTES=10-").last == 99);
  CHECK(r("bytes=-10").first == 90);
  CHECK(r("bytes=-1000").first == 0);  // a suffix longer than the body: all of it
  CHECK(r("bytes=5-99999999999999999999999999999").last == 99);
  CHECK(r("bytes=100-").kind == K::unsatisfiable);
  CHECK(r("bytes=99999999999999999999999999-").kind == K::unsatisfiable);
  CHECK(r("bytes=-0").kind == K::unsatisfiable);
  CHECK(r("bytes=0-0", 0).kind == K::unsatisfiable);
  for (const char* ignored :
       {"bytes=0-1,5-6", "bytes=9-2", "items=0-1", "bytes=a-b", "bytes=-", "bytes=1", "bytes=+1-2"})
    CHECK_MESSAGE(r(ignored).kind == K::whole, ignored);
}

TEST_CASE("folder listing: folders from rows and from files' paths, children only when recursive") {
  const std::vector<StoredFile> files = {
      {"top.gcode", "d1", 5, 1}, {"a/b/deep.gcode", "d2", 7, 2}, {"a/x.gcode", "d3", 11, 3}};
  const std::vector<std::string> folders = {"empty"};  // "a" and "a/b" have no rows: they come from the files
  const auto file = [](const StoredFile& f) { return json{{"path", f.name}, {"type", "machinecode"}}; };
  const auto folder = [](const std::string& p) { return json{{"path", p}, {"type", "folder"}}; };
  const json top = folder_entries(files, folders, "", false, file, folder);
  REQUIRE(top.size() == 3);
  CHECK(top[0]["path"] == "a");
  CHECK(top[0]["size"] == 18);
  CHECK_FALSE(top[0].contains("children"));
  CHECK(top[1]["path"] == "empty");
  CHECK(top[1]["size"] == 0);
  CHECK(top[2]["path"] == "top.gcode");
  const json tree = folder_entries(files, folders, "", true, file, folder);
  CHECK(tree[0]["children"][0]["path"] == "a/b");
  CHECK(tree[0]["children"][0]["children"][0]["path"] == "a/b/deep.gcode");
  CHECK(tree[0]["children"][1]["path"] == "a/x.gcode");
  CHECK(tree[1]["children"].empty());
  CHECK(folder_entries(files, folders, "a/b", false, file, folder).size() == 1);
}

TEST_CASE("router: a last \"{path*}\" segment takes the rest of the path") {
  PathParams p;
  CHECK(match_pattern("/api/files/local/{path*}", "/api/files/local/a/b/c.gcode", p));
  CHECK(p.at("path") == "a/b/c.gcode");
  CHECK(match_pattern("/api/files/local/{path*}", "/api/files/local/x", p));
  CHECK(p.at("path") == "x");
  CHECK_FALSE(match_pattern("/api/files/local/{path*}", "/api/files/local/", p));
  CHECK_FALSE(match_pattern("/api/files/local/{path*}", "/api/files/local", p));
}
