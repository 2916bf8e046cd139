// ZipWriter (PKWARE APPNOTE 6.3: method 0 "stored", no data descriptors, UTF-8 names).
#include "core/export/zip_writer.hpp"

#include <zlib.h>

#include <stdexcept>

namespace salient::core {
namespace {

void put16(std::string& out, std::uint32_t v) {
  out.push_back(static_cast<char>(v & 0xff));
  out.push_back(static_cast<char>((v >> 8) & 0xff));
}
void put32(std::string& out, std::uint32_t v) {
  put16(out, v & 0xffff);
  put16(out, v >> 16);
}

constexpr std::uint32_t dos_date =
    (46u << 9) | (11u << 5) | 22u;  // 2026-11-22: fixed, so builds are reproducible

}  // namespace

void ZipWriter::add(std::string name, std::string_view data) {
  if (data.size() > 0xffffffffu || body_.size() > 0xffffffffu)
    throw std::length_error("ZipWriter: entry too large (no ZIP64)");
  Entry e{std::move(name),
          static_cast<std::uint32_t>(
              crc32(0L, reinterpret_cast<const Bytef*>(data.data()), static_cast<uInt>(data.size()))),
          static_cast<std::uint32_t>(data.size()), static_cast<std::uint32_t>(body_.size())};
  put32(body_, 0x04034b50);
  put16(body_, 20);      // version needed
  put16(body_, 0x0800);  // UTF-8 names
  put16(body_, 0);       // stored
  put16(body_, 0);       // time
  put16(body_, dos_date);
  put32(body_, e.crc);
  put32(body_, e.size);
  put32(body_, e.size);
  put16(body_, static_cast<std::uint32_t>(e.name.size()));
  put16(body_, 0);
  body_ += e.name;
  body_.append(data);
  entries_.push_back(std::move(e));
}

std::string ZipWriter::finish() const {
  std::string out = body_, dir;
  for (const Entry& e : entries_) {
    put32(dir, 0x02014b50);
    put16(dir, 20);
    put16(dir, 20);
    put16(dir, 0x0800);
    put16(dir, 0);
    put16(dir, 0);
    put16(dir, dos_date);
    put32(dir, e.crc);
    put32(dir, e.size);
    put32(dir, e.size);
    put16(dir, static_cast<std::uint32_t>(e.name.size()));
    put16(dir, 0);
    put16(dir, 0);
    put16(dir, 0);
    put16(dir, 0);
    put32(dir, 0);
    put32(dir, e.offset);
    dir += e.name;
  }
  const auto dir_offset = static_cast<std::uint32_t>(out.size());
  out += dir;
  put32(out, 0x06054b50);
  put16(out, 0);
  put16(out, 0);
  put16(out, static_cast<std::uint32_t>(entries_.size()));
  put16(out, static_cast<std::uint32_t>(entries_.size()));
  put32(out, static_cast<std::uint32_t>(dir.size()));
  put32(out, dir_offset);
  put16(out, 0);
  return out;
}

}  // namespace salient::core
