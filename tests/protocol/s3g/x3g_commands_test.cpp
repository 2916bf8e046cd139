#include "protocol/s3g/x3g_commands.hpp"

#include <doctest/doctest.h>

#include <string>

#include "protocol/s3g/packet.hpp"
#include "protocol/s3g/x3g_program.hpp"

using namespace salient::protocol::s3g;

namespace {
std::string point() {
  std::string p(1, static_cast<char>(155));
  for (int i = 0; i < 5; ++i) put_i32(p, i * 100);
  put_u32(p, 1234);
  put_u8(p, 0x18);
  put_f32(p, 2.5f);
  put_u16(p, 640);
  return p;
}
std::string build_start(const std::string& name) {
  std::string p(1, static_cast<char>(153));
  put_u32(p, 0);
  return p + name + '\0';
}
std::string tool_action(int len) {
  std::string p = {static_cast<char>(136), 0, 3, static_cast<char>(len)};
  return p + std::string(static_cast<std::size_t>(len), '\x01');
}
}  // namespace

TEST_CASE("an x3g stream splits into its actions, fixed and variable length") {
  CHECK(point().size() == 32);
  const std::string file =
      build_start("model") + point() + tool_action(2) + point() + std::string{char(154), 0};
  const auto actions = split_x3g(file);
  REQUIRE(actions.size() == 5);
  CHECK(actions[0] == build_start("model"));
  CHECK(actions[1] == point());
  CHECK(actions[2].size() == 6);
  CHECK(actions[4].size() == 2);
  CHECK(split_x3g("").empty());
}

TEST_CASE("bytes that are not whole known actions are refused with their offset") {
  try {
    split_x3g(point() + std::string(1, '\x07'));  // 7 is a query, not an action
    FAIL("no error");
  } catch (const X3gError& e) {
    CHECK(e.offset == 32);
    CHECK(std::string(e.what()).find("not an s3g action") != std::string::npos);
  }
  try {
    split_x3g(point().substr(0, 20));
    FAIL("no error");
  } catch (const X3gError& e) {
    CHECK(e.offset == 0);
    CHECK(std::string(e.what()).find("cut short") != std::string::npos);
  }
  CHECK_THROWS_AS(split_x3g(tool_action(29)), X3gError);  // 33 bytes: more than a packet
  CHECK_THROWS_AS(split_x3g(build_start(std::string(30, 'n'))), X3gError);
  CHECK_NOTHROW(split_x3g(build_start(std::string(26, 'n'))));  // exactly 32
  CHECK(action_length(point().substr(0, 31)) == std::nullopt);
  CHECK(action_length(point()) == 32u);
}

TEST_CASE("an x3g program maps its actions to commands, and resumes at a command's first action") {
  X3gProgram p;
  p.actions = {point(), point(), point(), point()};
  p.source = {0, 2, 2, 5};
  p.commands = 7;
  CHECK(p.command_of(2) == 2);
  CHECK(p.first_action_of(0) == 0);
  CHECK(p.first_action_of(1) == 1);
  CHECK(p.first_action_of(3) == 3);
  CHECK(p.first_action_of(6) == 4);
  const X3gProgram f = X3gProgram::from_x3g(p.bytes());
  CHECK(f.actions == p.actions);
  CHECK(f.commands == 4);
  CHECK(f.command_of(3) == 3);
  CHECK(f.first_action_of(9) == 4);
}
