// resume_prelude for s3g over an x3g written by GPX-shaped actions: what it restores.
#include "protocol/s3g/resume_prelude.hpp"

#include <doctest/doctest.h>

#include "protocol/s3g/packet.hpp"
#include "protocol/s3g/s3g_session.hpp"
#include "protocol/s3g/x3g_commands.hpp"

using namespace salient::protocol::s3g;

namespace {

std::string point(std::int32_t x, std::int32_t y, std::int32_t z, std::uint8_t relative = 0x18) {
  std::string a(1, static_cast<char>(155));
  put_i32(a, x), put_i32(a, y), put_i32(a, z), put_i32(a, -5), put_i32(a, 0);
  put_u32(a, 1000), put_u8(a, relative), put_f32(a, 1.0f), put_u16(a, 640);
  return a;
}

std::string tool(std::uint8_t cmd, std::int16_t v) {
  std::string a = {static_cast<char>(136), 0, static_cast<char>(cmd), 2};
  put_i16(a, v);
  return a;
}

std::string bytes(std::initializer_list<int> b) {
  std::string out;
  for (int v : b) out.push_back(static_cast<char>(v));
  return out;
}

std::int32_t i32_at(const std::string& a, std::size_t at) {
  return get_i32(a, at);
}

X3gProgram program() {
  X3gProgram p;
  const std::string home_xy = bytes({132, 3, 0x7E, 1, 0, 0, 0x2D, 0});
  const std::string home_z = bytes({131, 4, 0x88, 0, 0, 0, 0x2D, 0});
  const std::string recall = bytes({144, 0x1F});
  p.actions = {tool(31, 110), tool(3, 230),           home_xy,          home_z,
               recall,        point(100, 200, 400),   tool(3, 215),     point(50, 60, 800),
               tool(12, 0),   point(10, 10, 0, 0x1F), point(1, 2, 1200)};
  p.source = {0, 1, 2, 2, 3, 4, 5, 6, 7, 8, 9};
  p.commands = 10;
  return p;
}

}  // namespace

TEST_CASE(
    "s3g resume prelude: temperatures, lift, the file's homing, waits, back over the last point and down") {
  const X3gProgram p = program();
  CHECK(resume_prelude(p, 0).empty());
  const auto out = resume_prelude(p, 9);  // after command 8: the relative move (60, 70, 800)
  for (const auto& a : out) {
    const auto n = action_length(a);
    REQUIRE(n);
    CHECK(*n == a.size());
  }
  REQUIRE(out.size() == 12);
  CHECK(out[0] == tool(31, 110));
  CHECK(out[1] == tool(3, 215));
  CHECK(static_cast<std::uint8_t>(out[2][0]) == 155);
  CHECK(static_cast<std::uint8_t>(out[2][25]) == 0x1F);  // a delta: the head may be anywhere
  CHECK(i32_at(out[2], 9) == 400);                       // 1 mm at 400 steps/mm
  CHECK(out[3] == p.actions[2]);
  CHECK(out[4] == p.actions[3]);
  CHECK(out[5] == p.actions[4]);
  CHECK(static_cast<std::uint8_t>(out[6][0]) == 141);
  CHECK(static_cast<std::uint8_t>(out[7][0]) == 135);
  CHECK(out[8] == bytes({136, 0, 12, 1, 0}));
  // Z first (X Y unchanged), then over the last X Y, then down to the last Z.
  CHECK(static_cast<std::uint8_t>(out[9][25]) == 0x1B);
  CHECK(i32_at(out[9], 9) == 1200);
  CHECK(i32_at(out[10], 1) == 60);
  CHECK(i32_at(out[10], 5) == 70);
  CHECK(i32_at(out[10], 9) == 1200);
  CHECK(i32_at(out[11], 9) == 800);
}

TEST_CASE("s3g resume prelude: the last action goes down to the last Z, and the session takes it all") {
  const X3gProgram p = program();
  auto out = resume_prelude(p, 10);
  REQUIRE(!out.empty());
  const std::string& last = out.back();
  CHECK(i32_at(last, 1) == 1);
  CHECK(i32_at(last, 5) == 2);
  CHECK(i32_at(last, 9) == 1200);
  S3gSession s;
  CHECK_NOTHROW(s.begin(std::make_shared<const X3gProgram>(p), Millis(0), 10, out));
}
