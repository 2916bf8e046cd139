#include "protocol/s3g/packet.hpp"

#include <doctest/doctest.h>

#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "protocol/s3g/s3g_codes.hpp"

using namespace salient::protocol::s3g;

namespace {
std::string bytes(std::initializer_list<int> b) {
  std::string s;
  for (int x : b) s += static_cast<char>(x);
  return s;
}
}  // namespace

TEST_CASE("CRC-8/Maxim and framing match the protocol's examples") {
  CHECK(crc8("123456789") == 0xA1);
  CHECK(frame(bytes({0x02})) == bytes({0xD5, 0x01, 0x02, 0xBC}));  // query 2
  CHECK(frame(bytes({0x81})) == bytes({0xD5, 0x01, 0x81, 0xD2}));  // ok
  CHECK(frame(bytes({0x82})) == bytes({0xD5, 0x01, 0x82, 0x30}));  // buffer full
  CHECK(frame(bytes({0x81, 0x00, 0x02, 0x00, 0x00})) ==
        bytes({0xD5, 0x05, 0x81, 0x00, 0x02, 0x00, 0x00, 0x49}));
  CHECK_THROWS_AS(frame(""), std::invalid_argument);
  CHECK_THROWS_AS(frame(std::string(33, 'x')), std::invalid_argument);
  CHECK_NOTHROW(frame(std::string(32, 'x')));
}

TEST_CASE("the decoder finds every packet in a stream of garbage and drops the damaged ones") {
  std::mt19937 rng(7);
  std::vector<std::string> sent;
  std::string stream;
  std::size_t damaged = 0;
  for (int i = 0; i < 2000; ++i) {
    if (rng() % 4 == 0)
      for (int g = 0; g < 5; ++g) stream += static_cast<char>(rng() % 0xD5);  // garbage without D5
    std::string payload;
    const std::size_t n = 1 + rng() % 32;
    for (std::size_t k = 0; k < n; ++k) payload += static_cast<char>(rng());
    std::string f = frame(payload);
    if (rng() % 10 == 0) {
      f.back() = static_cast<char>(f.back() ^ 0x5A);  // a bad CRC
      ++damaged;
    } else {
      sent.push_back(payload);
    }
    stream += f;
  }
  PacketDecoder d;
  std::vector<std::string> got;
  std::size_t crc_errors = 0;
  for (unsigned char b : stream) {
    auto r = d.feed(b);
    if (r.payload) got.push_back(*r.payload);
    if (r.error == PacketDecoder::Error::bad_crc) ++crc_errors;
  }
  // A damaged packet's payload may hold D5 bytes that start a false packet: those are caught by
  // their CRC (a 1-in-256 chance each to pass); what matters is that every good packet is found.
  std::size_t found = 0, j = 0;
  for (const auto& p : got)
    if (j < sent.size() && p == sent[j]) ++found, ++j;
  CHECK(found >= sent.size() - damaged);
  CHECK(crc_errors >= damaged / 2);
  CHECK(d.skipped() > 0);
}

TEST_CASE("a length of 0 or over 32 is refused and the search goes on") {
  PacketDecoder d;
  CHECK(d.feed(0xD5).error == PacketDecoder::Error::none);
  CHECK(d.feed(33).error == PacketDecoder::Error::bad_length);
  CHECK_FALSE(d.in_packet());
  for (unsigned char b : frame(bytes({0x81}))) {
    auto r = d.feed(b);
    if (r.payload) CHECK(*r.payload == bytes({0x81}));
  }
}

TEST_CASE("little-endian fields round-trip, and reading past the end throws") {
  std::string s;
  put_i32(s, -123456);
  put_u16(s, 0xBEEF);
  put_f32(s, 1.5f);
  put_i16(s, -2);
  CHECK(s.size() == 12);
  CHECK(static_cast<unsigned char>(s[4]) == 0xEF);
  std::size_t at = 0;
  CHECK(get_i32(s, at) == -123456);
  CHECK(get_u16(s, at) == 0xBEEF);
  CHECK(get_f32(s, at) == 1.5f);
  CHECK(get_i16(s, at) == -2);
  CHECK_THROWS_AS(get_u8(s, at), std::out_of_range);
}

TEST_CASE("every reply code has its host action") {
  CHECK(action_of(0x81) == ReplyAction::accept);
  for (int c : {0x80, 0x83, 0x88, 0x8C})
    CHECK(action_of(static_cast<std::uint8_t>(c)) == ReplyAction::resend);
  CHECK(action_of(0x82) == ReplyAction::wait_resend);
  for (int c : {0x89, 0x8A, 0x8B}) CHECK(action_of(static_cast<std::uint8_t>(c)) == ReplyAction::stop);
  for (int c : {0x84, 0x85, 0x87, 0x86, 0x91, 0x00})
    CHECK(action_of(static_cast<std::uint8_t>(c)) == ReplyAction::fatal);
  CHECK(reply_name(0x8B).find("heater") != std::string_view::npos);
  CHECK_FALSE(is_reply_code(0x86));
}
