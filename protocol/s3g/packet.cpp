#include "protocol/s3g/packet.hpp"

#include <bit>
#include <cstring>
#include <stdexcept>
#include <string>

namespace salient::protocol::s3g {

std::uint8_t crc8(std::string_view bytes) {
  std::uint8_t crc = 0;
  for (unsigned char b : bytes) {
    crc ^= b;
    for (int i = 0; i < 8; ++i) crc = (crc & 1) ? static_cast<std::uint8_t>((crc >> 1) ^ 0x8C) : crc >> 1;
  }
  return crc;
}

std::string frame(std::string_view payload) {
  if (payload.empty() || payload.size() > kMaxPayload)
    throw std::invalid_argument("s3g payload of " + std::to_string(payload.size()) + " bytes (1…32)");
  std::string out;
  out.reserve(payload.size() + 3);
  out += static_cast<char>(kStartByte);
  out += static_cast<char>(payload.size());
  out += payload;
  out += static_cast<char>(crc8(payload));
  return out;
}

PacketDecoder::Result PacketDecoder::feed(std::uint8_t byte) {
  switch (state_) {
    case State::start:
      if (byte == kStartByte)
        state_ = State::length;
      else
        ++skipped_;
      return {};
    case State::length:
      if (byte == 0 || byte > kMaxPayload) {
        state_ = State::start;
        return {std::nullopt, Error::bad_length};
      }
      length_ = byte;
      payload_.clear();
      state_ = State::payload;
      return {};
    case State::payload:
      payload_ += static_cast<char>(byte);
      if (payload_.size() == length_) state_ = State::crc;
      return {};
    case State::crc:
      state_ = State::start;
      if (byte != crc8(payload_)) return {std::nullopt, Error::bad_crc};
      return {std::move(payload_), Error::none};
  }
  return {};
}

namespace {

template <typename T>
void put_le(std::string& out, T v) {
  using U = std::make_unsigned_t<T>;
  auto u = static_cast<U>(v);
  for (std::size_t i = 0; i < sizeof(T); ++i) out += static_cast<char>((u >> (8 * i)) & 0xFF);
}

template <typename T>
T get_le(std::string_view in, std::size_t& at) {
  if (at + sizeof(T) > in.size()) throw std::out_of_range("s3g field past the end of its payload");
  using U = std::make_unsigned_t<T>;
  U u = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i)
    u |= static_cast<U>(static_cast<unsigned char>(in[at + i])) << (8 * i);
  at += sizeof(T);
  return static_cast<T>(u);
}

}  // namespace

void put_u8(std::string& out, std::uint8_t v) {
  out += static_cast<char>(v);
}
void put_u16(std::string& out, std::uint16_t v) {
  put_le(out, v);
}
void put_u32(std::string& out, std::uint32_t v) {
  put_le(out, v);
}
void put_i16(std::string& out, std::int16_t v) {
  put_le(out, v);
}
void put_i32(std::string& out, std::int32_t v) {
  put_le(out, v);
}
void put_f32(std::string& out, float v) {
  put_le(out, std::bit_cast<std::uint32_t>(v));
}
std::uint8_t get_u8(std::string_view in, std::size_t& at) {
  return get_le<std::uint8_t>(in, at);
}
std::uint16_t get_u16(std::string_view in, std::size_t& at) {
  return get_le<std::uint16_t>(in, at);
}
std::uint32_t get_u32(std::string_view in, std::size_t& at) {
  return get_le<std::uint32_t>(in, at);
}
std::int16_t get_i16(std::string_view in, std::size_t& at) {
  return get_le<std::int16_t>(in, at);
}
std::int32_t get_i32(std::string_view in, std::size_t& at) {
  return get_le<std::int32_t>(in, at);
}
float get_f32(std::string_view in, std::size_t& at) {
  return std::bit_cast<float>(get_le<std::uint32_t>(in, at));
}

}  // namespace salient::protocol::s3g
