// s3g packet framing: 0xD5, payload length (1…32), payload, CRC-8/Maxim of the payload. Pure
// functions and a byte-fed decoder: no I/O, no clock (the 200 ms packet timeout is the caller's).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace salient::protocol::s3g {

inline constexpr std::uint8_t kStartByte = 0xD5;
inline constexpr std::size_t kMaxPayload = 32;

// CRC-8 Dallas/Maxim (reflected polynomial 0x8C, init 0): "123456789" → 0xA1.
std::uint8_t crc8(std::string_view bytes);

// D5 len payload crc. The payload must be 1…32 bytes (std::invalid_argument otherwise).
std::string frame(std::string_view payload);

// Reassembles packets from a byte stream that may hold garbage: bytes before a start byte are
// skipped (counted), a bad length or CRC drops the packet (counted) and the search goes on.
class PacketDecoder {
 public:
  enum class Error { none, bad_length, bad_crc };
  struct Result {
    std::optional<std::string> payload;  // a whole packet
    Error error = Error::none;           // a packet that was dropped
  };

  // Feeds one byte; a packet, a dropped one, or nothing yet.
  Result feed(std::uint8_t byte);
  bool in_packet() const { return state_ != State::start; }  // a packet has begun and is not whole
  void reset() { state_ = State::start; }
  std::size_t skipped() const { return skipped_; }  // bytes outside any packet

 private:
  enum class State { start, length, payload, crc };
  State state_ = State::start;
  std::size_t length_ = 0, skipped_ = 0;
  std::string payload_;
};

// Little-endian fields, as every s3g integer and float is sent.
void put_u8(std::string& out, std::uint8_t v);
void put_u16(std::string& out, std::uint16_t v);
void put_u32(std::string& out, std::uint32_t v);
void put_i16(std::string& out, std::int16_t v);
void put_i32(std::string& out, std::int32_t v);
void put_f32(std::string& out, float v);
// Reads at `at` (and advances it); std::out_of_range when the bytes are not there.
std::uint8_t get_u8(std::string_view in, std::size_t& at);
std::uint16_t get_u16(std::string_view in, std::size_t& at);
std::uint32_t get_u32(std::string_view in, std::size_t& at);
std::int16_t get_i16(std::string_view in, std::size_t& at);
std::int32_t get_i32(std::string_view in, std::size_t& at);
float get_f32(std::string_view in, std::size_t& at);

}  // namespace salient::protocol::s3g
