#include "server/http/multipart.hpp"

#include <doctest/doctest.h>

#include <stdexcept>

using namespace salient::server;

TEST_CASE("multipart: curl's and PrusaSlicer's form bodies") {
  CHECK(multipart_boundary("multipart/form-data; boundary=------------------------abc123") ==
        "------------------------abc123");
  CHECK(multipart_boundary("multipart/form-data; boundary=\"quoted b\"") == "quoted b");
  CHECK_FALSE(multipart_boundary("application/json"));
  const std::string body =
      "--B\r\nContent-Disposition: form-data; name=\"print\"\r\n\r\ntrue\r\n"
      "--B\r\nContent-Disposition: form-data; name=\"path\"\r\n\r\n\r\n"
      "--B\r\nContent-Disposition: form-data; name=\"file\"; filename=\"my part.gcode\"\r\n"
      "Content-Type: application/octet-stream\r\n\r\nG28\r\nG1 X1\r\n\r\n--B--\r\n";
  const auto parts = parse_multipart(body, "B");
  REQUIRE(parts.size() == 3);
  CHECK(parts[0].name == "print");
  CHECK(parts[0].body == "true");
  CHECK(parts[1].body.empty());
  CHECK(parts[2].filename == "my part.gcode");
  CHECK(parts[2].content_type == "application/octet-stream");
  CHECK(parts[2].body == "G28\r\nG1 X1\r\n");  // bytes kept as sent, CRLF and all
}

TEST_CASE("multipart: malformed bodies are refused with a reason") {
  CHECK_THROWS_WITH_AS(parse_multipart("no boundary here", "B"), "multipart body without its boundary",
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(
      parse_multipart("--B\r\nContent-Disposition: form-data; name=\"a\"\r\n\r\nunfinished", "B"),
      "multipart body ends inside a part", std::invalid_argument);
  CHECK_THROWS_AS(parse_multipart("--B\r\nno colon\r\n\r\nx\r\n--B--", "B"), std::invalid_argument);
}

TEST_CASE("multipart: a parameter's text inside a quoted value is not a parameter (found by fuzzing)") {
  const std::string body =
      "--b\r\nContent-Disposition: form-data; filename=\"a; name=settings\"; "
      "name=\"file\"\r\n\r\nx\r\n--b--\r\n";
  const auto parts = parse_multipart(body, "b");
  REQUIRE(parts.size() == 1);
  CHECK(parts[0].name == "file");
  CHECK(parts[0].filename == "a; name=settings");
  CHECK(multipart_boundary("multipart/form-data; charset=utf-8; boundary=\"x;y\"") == "x;y");
}
