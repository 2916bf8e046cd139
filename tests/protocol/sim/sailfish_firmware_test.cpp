// SailfishFirmware driven directly (no pseudo-terminal): framed packets and time in, the replies a
// Sailfish board would send out, byte for byte, and the actions it ran.
#include "protocol/sim/sailfish_firmware.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <random>
#include <stdexcept>

#include "protocol/s3g/packet.hpp"
#include "protocol/sim/sailfish_faults.hpp"

using namespace salient::protocol::sim;
namespace s3g = salient::protocol::s3g;

namespace {

constexpr Micros ms(long long n) {
  return Micros(n * 1000);
}

std::string bytes(std::initializer_list<int> b) {
  std::string s;
  for (int v : b) s += static_cast<char>(v);
  return s;
}

// The reply payloads in `out`, in order; stops at the first byte that is not a whole reply.
std::vector<std::string> replies(const std::string& out) {
  std::vector<std::string> r;
  s3g::PacketDecoder d;
  for (unsigned char c : out)
    if (auto got = d.feed(c); got.payload) r.push_back(*got.payload);
  return r;
}

// Sends one packet at `t` and returns the payloads of the replies that came.
std::vector<std::string> ask(SailfishFirmware& fw, const std::string& payload, Micros t) {
  fw.receive(s3g::frame(payload), t);
  fw.advance(t);
  return replies(fw.take_output(t));
}

// The first byte of the one reply to `payload`; 0 when none came.
int code(SailfishFirmware& fw, const std::string& payload, Micros t) {
  const auto r = ask(fw, payload, t);
  return r.size() == 1 ? static_cast<unsigned char>(r[0][0]) : 0;
}

std::string delay(std::uint32_t millis) {
  std::string a = bytes({133});
  s3g::put_u32(a, millis);
  return a;
}

std::string set_temperature(int command, int degrees) {  // 3: nozzle, 31: platform
  std::string a = bytes({136, 0, command, 2});
  s3g::put_i16(a, static_cast<std::int16_t>(degrees));
  return a;
}

std::string wait_for(int id, std::uint16_t timeout_s) {  // 135: nozzle, 141: platform
  std::string a = bytes({id, 0});
  s3g::put_u16(a, 100);
  s3g::put_u16(a, timeout_s);
  return a;
}

std::string point(std::array<std::int32_t, 5> p, std::uint32_t dda, std::uint8_t relative, float mm,
                  std::uint16_t feed64) {
  std::string a = bytes({155});
  for (auto v : p) s3g::put_i32(a, v);
  s3g::put_u32(a, dda);
  s3g::put_u8(a, relative);
  s3g::put_f32(a, mm);
  s3g::put_u16(a, feed64);
  return a;
}

std::string build_start() {
  std::string a = bytes({153, 0, 0, 0, 0});
  return a + "t" + std::string(1, '\0');
}

std::string hex(const std::string& b) {
  static constexpr char d[] = "0123456789abcdef";
  std::string s;
  for (unsigned char c : b) s += d[c >> 4], s += d[c & 15];
  return s;
}

std::uint32_t free_space(SailfishFirmware& fw, Micros t) {
  const auto r = ask(fw, bytes({2}), t);
  REQUIRE(r.size() == 1);
  std::size_t at = 1;
  return s3g::get_u32(r[0], at);
}

struct Stats {
  int state;
  std::uint32_t line;
};
Stats build_stats(SailfishFirmware& fw, Micros t) {
  const auto r = ask(fw, bytes({24}), t);
  REQUIRE(r.size() == 1);
  REQUIRE(r[0].size() == 12);
  std::size_t at = 4;
  return {static_cast<unsigned char>(r[0][1]), s3g::get_u32(r[0], at)};
}

int tool_value(SailfishFirmware& fw, int command, Micros t) {
  const auto r = ask(fw, bytes({10, 0, command}), t);
  REQUIRE(r.size() == 1);
  std::size_t at = 1;
  return r[0].size() == 2 ? s3g::get_u8(r[0], at) : s3g::get_i16(r[0], at);
}

SailfishConfig timed(double time_scale, double heat_time_scale = 0) {
  SailfishConfig c;
  c.time_scale = time_scale;
  c.heat_time_scale = heat_time_scale;
  return c;
}

SailfishConfig with_faults(const std::string& spec) {
  SailfishConfig c;
  c.faults = parse_sailfish_faults(spec);
  return c;
}

}  // namespace

TEST_CASE("every query is answered with Sailfish's layout") {
  SailfishFirmware fw({});
  const Micros t{0};
  auto one = [&](const std::string& q) {
    const auto r = ask(fw, q, t);
    REQUIRE(r.size() == 1);
    return r[0];
  };
  CHECK(one(bytes({0, 100, 0})) == bytes({0x81, 0xC3, 0x02}));  // 707
  CHECK(one(bytes({0, 25, 0})) == bytes({0x81, 0, 0}));         // ReplicatorG 0025 is told 0
  CHECK(one(bytes({27, 100, 0})) == bytes({0x81, 0xC3, 0x02, 0, 0, 0x80, 0, 0, 0}));
  CHECK(one(bytes({1})) == bytes({0x81}));
  CHECK(one(bytes({2})) == bytes({0x81, 0, 2, 0, 0}));  // 512 free
  CHECK(one(bytes({11})) == bytes({0x81, 1}));
  CHECK(one(bytes({21})) == std::string(1, '\x81') + std::string(22, '\0'));
  CHECK(one(bytes({22, 3})) == bytes({0x81, 0}));
  CHECK(one(bytes({23})) == bytes({0x81, 0}));
  CHECK(one(bytes({24})) == std::string(1, '\x81') + std::string(11, '\0'));
  CHECK(one(bytes({10, 0, 2})) == bytes({0x81, 21, 0}));  // the nozzle at 21 °C
  CHECK(one(bytes({10, 0, 30})) == bytes({0x81, 21, 0}));
  CHECK(one(bytes({10, 0, 32})) == bytes({0x81, 0, 0}));
  CHECK(one(bytes({10, 0, 33})) == bytes({0x81, 0, 0}));
  CHECK(one(bytes({10, 0, 22})) == bytes({0x81, 1}));  // no target: ready
  CHECK(one(bytes({10, 0, 35})) == bytes({0x81, 1}));
  CHECK(one(bytes({10, 0, 99})) == bytes({0x85}));  // an unknown tool query
  CHECK(one(bytes({10, 0})) == bytes({0x85}));      // too short for its fields
  CHECK(one(bytes({99})) == bytes({0x85}));         // an unknown query
  CHECK(fw.stats().unsupported == 3);
  CHECK(fw.stats().packets_received == 19);
}

TEST_CASE("the ring takes an action only when all of it fits in 512 bytes") {
  SailfishFirmware fw(timed(1));
  Micros t{0};
  CHECK(code(fw, delay(10000), t) == 0x81);  // starts at once, so leaves the ring: 10 s
  CHECK(free_space(fw, t) == 512);
  // 102 delays of 5 bytes: 510 bytes, 2 left.
  for (int i = 0; i < 102; ++i) REQUIRE(code(fw, delay(1), t) == 0x81);
  CHECK(free_space(fw, t) == 2);
  CHECK(code(fw, delay(1), t) == 0x82);  // 5 bytes do not fit: refused, not queued
  CHECK(free_space(fw, t) == 2);
  CHECK(code(fw, bytes({137, 0x1F}), t) == 0x81);  // 2 bytes fit exactly
  CHECK(free_space(fw, t) == 0);
  CHECK(code(fw, bytes({137, 0x1F}), t) == 0x82);
  CHECK(fw.stats().buffer_full_sent == 2);
  CHECK(fw.ring_used() == 512);
  CHECK(fw.take_executed().size() == 1);
  // The first delay ends at 10 s; the next one starts and leaves the ring.
  t = ms(9999);
  fw.advance(t);
  CHECK(fw.take_executed().empty());
  CHECK(fw.next_wakeup() == ms(10000));
  t = ms(10000);
  fw.advance(t);
  CHECK(fw.take_executed() == std::vector<std::string>{hex(delay(1))});
  CHECK(free_space(fw, t) == 5);
}

TEST_CASE("actions take their real durations scaled by time_scale") {
  SailfishFirmware fw(timed(0.5));
  Micros t{0};
  const std::string ten_mm = point({889, 0, 0, 0, 0}, 1000, 0x18, 10.0f, 640);       // 10 mm at 10 mm/s: 1 s
  const std::string by_rate = point({889 + 2000, 0, 0, 0, 0}, 1000, 0x18, 0.0f, 0);  // 2000 steps at 1000/s
  REQUIRE(code(fw, ten_mm, t) == 0x81);
  REQUIRE(code(fw, by_rate, t) == 0x81);
  REQUIRE(code(fw, delay(300), t) == 0x81);
  CHECK(fw.take_executed().size() == 1);
  CHECK(fw.next_wakeup() == ms(500));
  fw.advance(ms(499));
  CHECK(fw.take_executed().empty());
  fw.advance(ms(500));
  CHECK(fw.take_executed() == std::vector<std::string>{hex(by_rate)});
  CHECK(fw.next_wakeup() == ms(1500));  // 2 s of steps, scaled
  fw.advance(ms(1500));
  CHECK(fw.take_executed() == std::vector<std::string>{hex(delay(300))});
  CHECK(code(fw, bytes({11}), ms(1500)) == 0x81);
  CHECK(ask(fw, bytes({11}), ms(1649))[0][1] == 0);  // the delay still runs
  CHECK(ask(fw, bytes({11}), ms(1650))[0][1] == 1);
  CHECK(build_stats(fw, ms(1650)).line == 3);
  CHECK(fw.position()[0] == 2889);
}

TEST_CASE("heater waits hold the ring until the target is reached, or their timeout") {
  SailfishFirmware fw(timed(0, 1));  // moves instant, heating in real time
  Micros t{0};
  REQUIRE(code(fw, set_temperature(3, 81), t) == 0x81);
  REQUIRE(code(fw, wait_for(135, 65535), t) == 0x81);
  REQUIRE(code(fw, delay(0), t) == 0x81);
  CHECK(fw.take_executed().size() == 2);  // the wait holds the delay behind it
  CHECK(free_space(fw, t) == 507);
  CHECK(tool_value(fw, 2, ms(10000)) == 51);  // 3 °C/s from 21
  CHECK(tool_value(fw, 22, ms(10000)) == 0);
  CHECK(tool_value(fw, 32, ms(10000)) == 81);
  fw.advance(ms(19300));
  CHECK(fw.take_executed().empty());
  // Ready within 2 °C: at 79 °C, 19.33 s in.
  CHECK(fw.next_wakeup() > ms(19300));
  CHECK(fw.next_wakeup() <= ms(19400));
  fw.advance(fw.next_wakeup());
  CHECK(fw.take_executed() == std::vector<std::string>{hex(delay(0))});
  CHECK(tool_value(fw, 22, ms(19400)) == 1);

  // The platform at 1 °C/s would take 79 s; its wait gives up after 5.
  REQUIRE(code(fw, set_temperature(31, 100), ms(20000)) == 0x81);
  REQUIRE(code(fw, wait_for(141, 5), ms(20000)) == 0x81);
  REQUIRE(code(fw, delay(0), ms(20000)) == 0x81);
  fw.take_executed();
  fw.advance(ms(24999));
  CHECK(fw.take_executed().empty());
  fw.advance(ms(25000));
  CHECK(fw.take_executed().size() == 1);
  CHECK(tool_value(fw, 30, ms(25000)) == 26);
  CHECK(tool_value(fw, 35, ms(25000)) == 0);
}

TEST_CASE("pause toggles only while building and holds execution while the ring still accepts") {
  SailfishFirmware fw({});
  Micros t{0};
  CHECK(code(fw, bytes({8}), t) == 0x81);  // not building: ignored, answered all the same
  CHECK(build_stats(fw, t).state == 0);
  REQUIRE(code(fw, build_start(), t) == 0x81);
  CHECK(build_stats(fw, t).state == 1);
  CHECK(code(fw, bytes({8}), t) == 0x81);
  CHECK(build_stats(fw, t).state == 3);
  fw.take_executed();
  CHECK(code(fw, delay(5), t) == 0x81);
  fw.advance(ms(1000));
  CHECK(fw.take_executed().empty());
  CHECK(free_space(fw, t) == 507);
  CHECK(code(fw, bytes({8}), t) == 0x81);
  CHECK(build_stats(fw, t).state == 1);
  CHECK(fw.take_executed() == std::vector<std::string>{hex(delay(5))});
  REQUIRE(code(fw, bytes({154, 0}), t) == 0x81);
  CHECK(build_stats(fw, t).state == 2);
  CHECK(build_stats(fw, t).line == 3);
}

TEST_CASE("abort clears the ring, stops the motion and turns the heaters off") {
  SailfishFirmware fw(timed(1, 1));
  Micros t{0};
  REQUIRE(code(fw, build_start(), t) == 0x81);
  REQUIRE(code(fw, set_temperature(3, 200), t) == 0x81);
  REQUIRE(code(fw, set_temperature(31, 100), t) == 0x81);
  REQUIRE(code(fw, delay(60000), t) == 0x81);
  for (int i = 0; i < 5; ++i) REQUIRE(code(fw, delay(1000), t) == 0x81);
  t = ms(3000);
  CHECK(tool_value(fw, 2, t) == 30);
  CHECK(code(fw, bytes({7}), t) == 0x81);
  CHECK(free_space(fw, t) == 512);
  CHECK(ask(fw, bytes({11}), t)[0][1] == 1);  // nothing runs
  CHECK(tool_value(fw, 32, t) == 0);
  CHECK(tool_value(fw, 33, t) == 0);
  CHECK(build_stats(fw, t).state == 4);
  CHECK(tool_value(fw, 2, ms(5000)) == 28);  // cooling, slower than it heats
  CHECK(fw.take_executed().size() == 4);
}

TEST_CASE("a packet not whole 200 ms after its first byte gets 8C") {
  SailfishFirmware fw({});
  const std::string q = s3g::frame(bytes({2}));
  fw.receive(q.substr(0, 3), Micros{0});
  fw.advance(Micros{0});
  CHECK(fw.next_wakeup() == ms(200));
  fw.advance(ms(199));
  CHECK(fw.take_output(ms(199)).empty());
  fw.advance(ms(200));
  CHECK(replies(fw.take_output(ms(200))) == std::vector<std::string>{bytes({0x8C})});
  CHECK(fw.stats().packet_timeouts == 1);
  // The late last byte is now a stray byte; then a whole packet is answered.
  fw.receive(q.substr(3), ms(201));
  fw.advance(ms(201));
  CHECK(replies(fw.take_output(ms(201))) == std::vector<std::string>{bytes({0x80})});
  CHECK(code(fw, bytes({2}), ms(202)) == 0x81);
}

TEST_CASE("a stray byte gets 80, a bad CRC 83, a length of 0 or over 32 gets 84") {
  SailfishFirmware fw({});
  const Micros t{0};
  fw.receive(bytes({0x01, 0x7F}), t);
  fw.advance(t);
  CHECK(replies(fw.take_output(t)) == std::vector<std::string>{bytes({0x80}), bytes({0x80})});
  std::string bad = s3g::frame(bytes({2}));
  bad.back() = static_cast<char>(bad.back() ^ 1);
  fw.receive(bad, t);
  fw.advance(t);
  CHECK(replies(fw.take_output(t)) == std::vector<std::string>{bytes({0x83})});
  fw.receive(bytes({0xD5, 33}), t);
  fw.receive(bytes({0xD5, 0}), t);
  fw.advance(t);
  CHECK(replies(fw.take_output(t)) == std::vector<std::string>{bytes({0x84}), bytes({0x84})});
  CHECK(fw.stats().stray_bytes == 2);
  CHECK(fw.stats().crc_errors == 1);
  CHECK(fw.stats().length_errors == 2);
  CHECK(fw.stats().packets_received == 0);
  CHECK(code(fw, bytes({2}), t) == 0x81);  // and the board goes on
}

TEST_CASE("with error_replies off the board is silent on what it cannot read, as Sailfish 7.7 is") {
  SailfishConfig c;
  c.error_replies = false;
  SailfishFirmware fw(c);
  std::string bad = s3g::frame(bytes({2}));
  bad.back() = static_cast<char>(bad.back() ^ 1);
  fw.receive(bytes({0x01}) + bad + bytes({0xD5, 40}) + bytes({0xD5, 1}), Micros{0});
  fw.advance(Micros{0});
  fw.advance(ms(200));
  CHECK(fw.take_output(ms(200)).empty());
  CHECK(fw.stats().stray_bytes == 1);
  CHECK(fw.stats().crc_errors == 1);
  CHECK(fw.stats().length_errors == 1);
  CHECK(fw.stats().packet_timeouts == 1);
  CHECK(code(fw, bytes({2}), ms(201)) == 0x81);
}

TEST_CASE("an unknown action id is acked and stalls the ring for ever, as on the board") {
  SailfishFirmware fw({});
  Micros t{0};
  CHECK(code(fw, bytes({200, 0}), t) == 0x81);  // never validated
  CHECK(code(fw, delay(1), t) == 0x81);
  fw.advance(ms(100000));
  CHECK(fw.take_executed().empty());
  CHECK(free_space(fw, ms(100000)) == 505);
  CHECK(ask(fw, bytes({11}), ms(100000))[0][1] == 0);
  // A half-sent action waits for the rest of its bytes, then runs.
  SailfishFirmware half({});
  const std::string d = delay(0x80808080);  // so that its second half reads as an action too
  CHECK(code(half, d.substr(0, 2), t) == 0x81);
  CHECK(half.take_executed().empty());
  CHECK(code(half, d.substr(2), t) == 0x81);
  CHECK(half.take_executed() == std::vector<std::string>{hex(d)});
}

TEST_CASE(
    "position: 155 is absolute in XYZ and relative in A and B, 140 sets it, homing sets the homed axes") {
  SailfishConfig c;
  SailfishFirmware fw(c);
  const Micros t{0};
  auto position = [&] {
    const auto r = ask(fw, bytes({21}), t);
    REQUIRE(r.size() == 1);
    REQUIRE(r[0].size() == 23);
    std::size_t at = 1;
    std::array<std::int32_t, 6> p{};
    for (int i = 0; i < 5; ++i) p[i] = s3g::get_i32(r[0], at);
    p[5] = s3g::get_u16(r[0], at);
    return p;
  };
  std::string set = bytes({140});
  for (int v : {1, 2, 3, 4, 5}) s3g::put_i32(set, v);
  REQUIRE(code(fw, set, t) == 0x81);
  CHECK(position() == std::array<std::int32_t, 6>{1, 2, 3, 4, 5, 0});
  REQUIRE(code(fw, point({100, 200, 300, -10, 0}, 1000, 0x18, 1.0f, 64), t) == 0x81);
  CHECK(position() == std::array<std::int32_t, 6>{100, 200, 300, -6, 5, 0});
  std::string home_max = bytes({132, 0x03});
  s3g::put_u32(home_max, 382);
  s3g::put_u16(home_max, 20);
  REQUIRE(code(fw, home_max, t) == 0x81);
  CHECK(position() == std::array<std::int32_t, 6>{c.home_steps[0], c.home_steps[1], 300, -6, 5, 0x0A});
  std::string home_min = bytes({131, 0x04});
  s3g::put_u32(home_min, 136);
  s3g::put_u16(home_min, 20);
  REQUIRE(code(fw, home_min, t) == 0x81);
  CHECK(position()[5] == 0x1A);  // X and Y at their max endstops, Z at its min
}

TEST_CASE("homing takes its step rate over the travel, capped by its timeout") {
  SailfishFirmware fw(timed(1));
  std::string home = bytes({132, 0x03});
  s3g::put_u32(home, 382);
  s3g::put_u16(home, 20);
  REQUIRE(code(fw, home, Micros{0}) == 0x81);
  // X: 246 mm × 88.89 steps/mm × 382 µs = 8.35 s.
  CHECK(fw.next_wakeup() > ms(8300));
  CHECK(fw.next_wakeup() < ms(8400));
  std::string slow = bytes({131, 0x04});
  s3g::put_u32(slow, 100000);  // 62,000 steps at 0.1 s each: its 20 s timeout ends it
  s3g::put_u16(slow, 20);
  fw.advance(ms(9000));
  REQUIRE(code(fw, slow, ms(9000)) == 0x81);
  CHECK(fw.next_wakeup() == ms(29000));
}

TEST_CASE("query 17 answers, then the board is deaf for a second and comes back empty") {
  SailfishFirmware fw(timed(1, 1));
  Micros t{0};
  REQUIRE(code(fw, build_start(), t) == 0x81);
  REQUIRE(code(fw, set_temperature(3, 200), t) == 0x81);
  REQUIRE(code(fw, delay(60000), t) == 0x81);
  REQUIRE(code(fw, delay(1), t) == 0x81);
  CHECK(build_stats(fw, t).line == 3);
  CHECK(code(fw, bytes({17}), t) == 0x81);
  CHECK(fw.state() == SailfishFirmware::State::resetting);
  CHECK(ask(fw, bytes({2}), ms(500)).empty());  // lost
  CHECK(fw.stats().bytes_ignored == 4);
  CHECK(fw.next_wakeup() == ms(1000));
  fw.advance(ms(1000));
  CHECK(fw.state() == SailfishFirmware::State::ready);
  CHECK(free_space(fw, ms(1000)) == 512);
  CHECK(build_stats(fw, ms(1000)).state == 0);
  CHECK(build_stats(fw, ms(1000)).line == 0);
  CHECK(tool_value(fw, 32, ms(1000)) == 0);
  CHECK(fw.stats().resets == 1);
}

TEST_CASE("the noise fault corrupts a received packet as a host would see it: never acked") {
  SailfishFirmware fw(with_faults("noise=1,seed=3"));
  Micros t{0};
  std::vector<int> seen(256, 0);
  for (int i = 0; i < 300; ++i) {
    fw.receive(s3g::frame(delay(static_cast<std::uint32_t>(i))), t);
    fw.advance(t);
    t += ms(250);  // past the packet timeout
    fw.advance(t);
    for (const auto& r : replies(fw.take_output(t))) ++seen[static_cast<unsigned char>(r[0])];
  }
  CHECK(seen[0x81] == 0);
  CHECK(seen[0x83] > 200);  // most bytes hit are the payload's or the CRC's
  CHECK(seen[0x80] > 0);    // the start byte, or what follows a shortened length
  CHECK(seen[0x8C] > 0);    // a longer length: the packet never completes
  CHECK(fw.stats().packets_corrupted == 300);
  CHECK(fw.take_executed().size() <= 3);  // only a shortened length can pass a CRC by chance
}

TEST_CASE("reply-noise corrupts replies, drop-reply loses them: the packets were acted on") {
  SailfishFirmware noisy(with_faults("reply-noise=1"));
  const Micros t{0};
  int intact = 0;
  for (int i = 0; i < 50; ++i) {
    noisy.receive(s3g::frame(delay(0)), t);
    noisy.advance(t);
    for (const auto& r : replies(noisy.take_output(t))) intact += r == bytes({0x81});
  }
  CHECK(intact == 0);
  CHECK(noisy.take_executed().size() == 50);
  CHECK(noisy.stats().replies_corrupted == 50);

  SailfishFirmware lossy(with_faults("drop-reply=1"));
  for (int i = 0; i < 10; ++i) CHECK(ask(lossy, delay(0), t).empty());
  CHECK(lossy.take_executed().size() == 10);
  CHECK(lossy.stats().replies_dropped == 10);
}

TEST_CASE("full-storm refuses actions that fit in bursts, and each action resent runs once") {
  SailfishFirmware fw(with_faults("full-storm=0.1,seed=5"));
  const Micros t{0};
  std::vector<std::string> sent;
  int burst = 0, longest = 0, bursts = 0;
  for (std::uint32_t i = 0; i < 400; ++i) {
    const std::string a = delay(i);
    int c;
    while ((c = code(fw, a, t)) == 0x82) ++burst;
    REQUIRE(c == 0x81);
    if (burst > 0) ++bursts, longest = std::max(longest, burst);
    burst = 0;
    sent.push_back(hex(a));
  }
  CHECK(fw.take_executed() == sent);
  CHECK(bursts > 5);
  CHECK(longest > 1);
  CHECK(longest <= 20);
  CHECK(fw.stats().storm_refusals == fw.stats().buffer_full_sent);
}

TEST_CASE("reset-at: after action N the ring is lost and the board is deaf for a second") {
  SailfishFirmware fw(with_faults("reset-at=3"));
  const Micros t{0};
  REQUIRE(code(fw, set_temperature(3, 200), t) == 0x81);
  for (int i = 0; i < 2; ++i) REQUIRE(code(fw, delay(0), t) == 0x81);  // the 2nd is action 3
  CHECK(fw.take_executed().size() == 3);
  CHECK(ask(fw, delay(0), ms(10)).empty());
  fw.advance(ms(1000));
  CHECK(build_stats(fw, ms(1000)).line == 0);
  CHECK(tool_value(fw, 32, ms(1000)) == 0);
  CHECK(code(fw, delay(0), ms(1000)) == 0x81);
  CHECK(fw.take_executed().size() == 1);
  CHECK(fw.stats().resets == 1);
}

TEST_CASE("cancel-at: the next packet gets 89 and is not run, then the board resets") {
  SailfishFirmware fw(with_faults("cancel-at=2"));
  const Micros t{0};
  REQUIRE(code(fw, build_start(), t) == 0x81);
  REQUIRE(code(fw, delay(0), t) == 0x81);  // action 2: the user cancels
  CHECK(code(fw, delay(0), t) == 0x89);
  CHECK(fw.take_executed().size() == 2);
  CHECK(fw.state() == SailfishFirmware::State::resetting);
  fw.advance(ms(1000));
  CHECK(build_stats(fw, ms(1000)).state == 0);
  // With no packet to tell, it resets 1 s after the cancel all the same.
  SailfishFirmware quiet(with_faults("cancel-at=1"));
  REQUIRE(code(quiet, build_start(), t) == 0x81);
  quiet.advance(ms(999));
  CHECK(quiet.stats().resets == 0);
  CHECK(quiet.build() == SailfishFirmware::Build::cancelled);
  quiet.advance(ms(1000));
  CHECK(quiet.stats().resets == 1);
  quiet.advance(ms(2000));
  CHECK(build_stats(quiet, ms(2000)).state == 0);
}

TEST_CASE("heater-fault-at: every packet from then on gets 8B, queries too") {
  SailfishFirmware fw(with_faults("heater-fault-at=2"));
  const Micros t{0};
  REQUIRE(code(fw, set_temperature(3, 200), t) == 0x81);
  REQUIRE(code(fw, delay(0), t) == 0x81);
  for (const std::string& p : {delay(0), bytes({2}), bytes({24}), bytes({0, 100, 0})})
    CHECK(code(fw, p, ms(5000)) == 0x8B);
  CHECK(fw.take_executed().size() == 2);
  CHECK(fw.state() == SailfishFirmware::State::heater_shutdown);
}

TEST_CASE("silent-after: the board hangs, nothing answers and nothing runs") {
  SailfishFirmware fw(with_faults("silent-after=1"));
  const Micros t{0};
  REQUIRE(code(fw, delay(0), t) == 0x81);
  CHECK(ask(fw, delay(0), t).empty());
  CHECK(ask(fw, bytes({2}), ms(60000)).empty());
  CHECK(fw.take_executed().size() == 1);
  CHECK(fw.state() == SailfishFirmware::State::silent);
}

TEST_CASE("the Sailfish fault spec refuses a bad value by name and repeats for a seed") {
  CHECK_THROWS_WITH_AS(parse_sailfish_faults("nosie=0.1"), doctest::Contains("unknown fault 'nosie'"),
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(parse_sailfish_faults("noise=2"), doctest::Contains("noise must be between 0 and 1"),
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(parse_sailfish_faults("reset-at=0"), doctest::Contains("reset-at must be a positive"),
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(parse_sailfish_faults("cancel-at"), doctest::Contains("cancel-at needs a value"),
                       std::invalid_argument);
  CHECK_THROWS_WITH_AS(parse_sailfish_faults("drop-reply=x"),
                       doctest::Contains("drop-reply=x is not a number"), std::invalid_argument);
  const SailfishFaults f = parse_sailfish_faults(
      "noise=0.02,reply-noise=0.03,drop-reply=0.01,full-storm=0.04,reset-at=5,cancel-at=6,heater-fault-at=7,"
      "silent-after=8,seed=9");
  CHECK(f.noise == 0.02);
  CHECK(f.full_storm == 0.04);
  CHECK(f.silent_after == 8);
  CHECK(f.seed == 9);
  auto run = [](const std::string& spec) {
    SailfishFirmware fw(with_faults(spec));
    std::string out;
    for (int i = 0; i < 200; ++i) {
      fw.receive(s3g::frame(delay(static_cast<std::uint32_t>(i))), ms(i * 300));
      fw.advance(ms(i * 300));
      fw.advance(ms(i * 300 + 250));
      out += fw.take_output(ms(i * 300 + 250));
    }
    return out;
  };
  CHECK(run("noise=0.1,reply-noise=0.1,seed=4") == run("noise=0.1,reply-noise=0.1,seed=4"));
  CHECK(run("noise=0.1,reply-noise=0.1,seed=4") != run("noise=0.1,reply-noise=0.1,seed=5"));
}

TEST_CASE("hostile input: random bytes and random packets never break the board, faults or not") {
  for (const char* spec : {"", "noise=0.05,reply-noise=0.05,drop-reply=0.05,full-storm=0.05,cancel-at=900",
                           "heater-fault-at=1500", "reset-at=700,seed=2"}) {
    CAPTURE(spec);
    std::mt19937_64 rng(11);
    SailfishConfig c = timed(0.001, 0.001);
    c.faults = parse_sailfish_faults(spec);
    const bool clean = std::string(spec).find("noise") == std::string::npos;
    SailfishFirmware fw(c);
    Micros t{0};
    s3g::PacketDecoder d;
    long long replies_seen = 0;
    for (int i = 0; i < 20000; ++i) {
      std::string b;
      const int kind = static_cast<int>(rng() % 4);
      const std::size_t n = 1 + rng() % 32;
      for (std::size_t k = 0; k < n; ++k) b += static_cast<char>(rng());
      if (kind == 0) b[0] = static_cast<char>(0x80 | (rng() % 32));  // near the real action ids
      if (kind == 1) b[0] = static_cast<char>(rng() % 30);           // near the real queries
      if (kind == 3)
        b = b.substr(0, 1 + rng() % 4);  // raw bytes, not a packet
      else
        b = s3g::frame(b);
      if (kind != 3 && b[2] == 17) continue;  // a reset, deaf for a second: slows the run only
      fw.receive(b, t);
      t += Micros(static_cast<long long>(rng() % 5000));
      fw.advance(t);
      for (unsigned char c : fw.take_output(t)) {
        const auto r = d.feed(c);
        if (clean) REQUIRE(r.error == s3g::PacketDecoder::Error::none);  // every reply is well framed
        if (r.payload) {
          ++replies_seen;
          const auto first = static_cast<unsigned char>((*r.payload)[0]);
          CHECK((first >= 0x80 && first <= 0x8C));
        }
      }
      REQUIRE(fw.ring_used() <= 512);
      REQUIRE(fw.next_wakeup() >= Micros{0});
    }
    CAPTURE(fw.stats().resets);
    CAPTURE(fw.stats().bytes_ignored);
    CAPTURE(fw.stats().packet_timeouts);
    CHECK(replies_seen > 5000);
    CHECK(fw.stats().packets_received > 2000);
  }
}

TEST_CASE("at 115200 baud a packet is read when its last byte has arrived, and its reply takes its time") {
  SailfishConfig c;
  c.baud = 115200;  // 11,520 bytes a second
  SailfishFirmware fw(c);
  fw.receive(s3g::frame(delay(0)), Micros{0});  // 8 bytes: 694 µs
  fw.advance(Micros{0});
  CHECK(fw.next_wakeup() == Micros{695});
  fw.advance(Micros{694});
  CHECK(fw.take_executed().empty());
  fw.advance(Micros{695});
  CHECK(fw.take_executed().size() == 1);
  CHECK(fw.next_wakeup() == Micros{695 + 348});  // the 4-byte reply
  CHECK(fw.take_output(Micros{1000}).size() == 3);
  CHECK(replies(fw.take_output(Micros{1043})).empty());
}

// The host's side of noise: a lone 83 or 8C means the board read the host's packet boundaries and
// is in step; anything else (80s, several replies) means its start byte or length was hit, and the
// board may now be inside a "packet" that began at a D5 within the host's bytes, which would
// swallow a quick resend, and the same way each time. The host waits out the packet timeout.
TEST_CASE(
    "under noise a host that resends, waiting out the packet timeout when out of step, runs each action "
    "once") {
  SailfishConfig c;
  c.faults = parse_sailfish_faults("noise=0.02,seed=21");
  SailfishFirmware fw(c);
  std::mt19937_64 rng(5);
  std::vector<std::string> sent;
  Micros t{0};
  long long resends = 0, waits = 0;
  for (int i = 0; i < 20000; ++i) {
    std::array<std::int32_t, 5> p{};
    for (auto& v : p) v = static_cast<std::int32_t>(rng() % 40000) - 20000;
    const std::string a = point(p, 1000 + static_cast<std::uint32_t>(rng() % 9000), 0x18, 10.0f, 3200);
    for (int tries = 0;; ++tries) {
      REQUIRE(tries < 10);
      fw.receive(s3g::frame(a), t);
      fw.advance(t);
      auto r = replies(fw.take_output(t));
      if (r.empty()) {  // a lengthened packet: it times out
        t += ms(200);
        fw.advance(t);
        r = replies(fw.take_output(t));
      }
      REQUIRE(!r.empty());
      t += ms(1);
      if (r.size() == 1 && r[0] == bytes({0x81})) break;
      for (const auto& one : r) REQUIRE(one != bytes({0x81}));
      ++resends;
      if (r.size() == 1 && (r[0] == bytes({0x83}) || r[0] == bytes({0x8C}))) continue;
      ++waits;
      t += ms(250);
      fw.advance(t);
      fw.take_output(t);
    }
    sent.push_back(hex(a));
  }
  CHECK(fw.take_executed() == sent);
  CHECK(fw.stats().false_packets == 0);
  CHECK(resends >= fw.stats().packets_corrupted);
  CHECK(fw.stats().packets_corrupted > 300);
  CHECK(waits > 0);
  CHECK(waits < resends / 4);
}

TEST_CASE("after a lost start byte a D5 inside the payload opens a packet that swallows a quick resend") {
  SailfishFirmware fw({});
  // A move whose X is 0x000020D5: its payload holds D5 20, the start of a 32-byte "packet".
  const std::string a = point({0x20D5, 0, 0, 0, 0}, 1000, 0x18, 1.0f, 64);
  const std::string f = s3g::frame(a);
  REQUIRE(f.find("\xD5\x20", 1) == 3);
  fw.receive(f.substr(1), Micros{0});  // the start byte was lost on the line
  fw.advance(Micros{0});
  // Its length and id are stray bytes; then the inner packet waits for 2 more bytes and its CRC.
  CHECK(replies(fw.take_output(Micros{0})) == std::vector<std::string>{bytes({0x80}), bytes({0x80})});
  // Resent at once, its start, length and id complete the open packet (bad CRC: a lone 83, as if
  // in step), and from its own D5 20 on it opens the same packet again, the same way each time.
  for (int i = 1; i <= 3; ++i) CHECK(ask(fw, a, ms(i)) == std::vector<std::string>{bytes({0x83})});
  CHECK(fw.take_executed().empty());
  // Waiting out the packet timeout puts it back in step.
  fw.advance(ms(203));
  CHECK(replies(fw.take_output(ms(203))) == std::vector<std::string>{bytes({0x8C})});
  CHECK(code(fw, a, ms(204)) == 0x81);
  CHECK(fw.take_executed() == std::vector<std::string>{hex(a)});
}
