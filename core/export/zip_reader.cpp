// ZipReader (PKWARE APPNOTE 6.3): the end record, then the central directory; each entry's data
// is found through its local header (whose own sizes may be zero when a data descriptor follows,
// so the directory's are used). Deflate (method 8) is raw DEFLATE, inflated by zlib.
#include "core/export/zip_reader.hpp"

#include <zlib.h>

#include <algorithm>

#include "core/common/input_error.hpp"

namespace salient::core {
namespace {

constexpr std::uint32_t end_signature = 0x06054b50, dir_signature = 0x02014b50, local_signature = 0x04034b50;

std::uint32_t get16(std::string_view s, std::size_t at) {
  return static_cast<unsigned char>(s[at]) | static_cast<unsigned char>(s[at + 1]) << 8;
}
std::uint32_t get32(std::string_view s, std::size_t at) {
  return get16(s, at) | get16(s, at + 2) << 16;
}

std::string inflate_raw(std::string_view in, std::size_t expected, std::size_t max_size,
                        const std::string& where) {
  z_stream z{};
  if (inflateInit2(&z, -MAX_WBITS) != Z_OK) throw InputError(where, {}, "cannot start inflating");
  std::string out(std::min<std::size_t>(expected, max_size) + 1, '\0');  // one byte more shows a longer entry
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
  z.avail_in = static_cast<uInt>(in.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = inflate(&z, Z_FINISH);
  const std::size_t produced = out.size() - z.avail_out;
  inflateEnd(&z);
  if (rc == Z_DATA_ERROR || rc == Z_NEED_DICT || rc == Z_MEM_ERROR)
    throw InputError(where, {}, "corrupt deflate data");
  if (produced > expected)
    throw InputError(where, {},
                     "inflates to more than the " + std::to_string(expected) + " bytes its directory says");
  if (rc != Z_STREAM_END) throw InputError(where, {}, "deflate data ends early (truncated)");
  if (produced != expected)
    throw InputError(
        where, {},
        "inflates to " + std::to_string(produced) + " bytes, its directory says " + std::to_string(expected));
  out.resize(produced);
  return out;
}

}  // namespace

ZipReader::ZipReader(std::string_view archive, std::string name) : archive_(archive), name_(std::move(name)) {
  const auto bad = [&](std::size_t at, const std::string& why) {
    return InputError(name_, InputLocation::at_byte(at), why);
  };
  if (archive.size() < 22) throw bad(0, "not a ZIP archive (too short)");
  // The end record is the last 22 bytes plus a comment of at most 65,535.
  std::size_t end = std::string_view::npos;
  const std::size_t lowest = archive.size() > 22 + 0xffff ? archive.size() - 22 - 0xffff : 0;
  for (std::size_t at = archive.size() - 22 + 1; at-- > lowest;)
    if (get32(archive, at) == end_signature) {
      end = at;
      break;
    }
  if (end == std::string_view::npos)
    throw bad(archive.size(), "not a ZIP archive (no end record: truncated?)");
  const std::uint32_t count = get16(archive, end + 10);
  const std::uint32_t dir_size = get32(archive, end + 12), dir_offset = get32(archive, end + 16);
  if (get16(archive, end + 4) != 0 || get16(archive, end + 6) != 0)
    throw bad(end, "multi-disk archives are not supported");
  if (std::uint64_t{dir_offset} + dir_size > end)
    throw bad(end, "central directory lies outside the archive (truncated?)");
  std::size_t at = dir_offset;
  for (std::uint32_t i = 0; i < count; ++i) {
    if (at + 46 > end || get32(archive, at) != dir_signature)
      throw bad(at, "malformed central directory entry");
    Entry e;
    e.flags = static_cast<std::uint16_t>(get16(archive, at + 8));
    e.method = static_cast<std::uint16_t>(get16(archive, at + 10));
    e.crc = get32(archive, at + 16);
    e.compressed = get32(archive, at + 20);
    e.size = get32(archive, at + 24);
    const std::size_t name_len = get16(archive, at + 28), extra = get16(archive, at + 30),
                      comment = get16(archive, at + 32);
    e.local_offset = get32(archive, at + 42);
    if (at + 46 + name_len + extra + comment > end)
      throw bad(at, "central directory entry runs past the directory");
    e.name = std::string(archive.substr(at + 46, name_len));
    if (e.compressed == 0xffffffffu || e.size == 0xffffffffu || e.local_offset == 0xffffffffu)
      throw bad(at, e.name + ": ZIP64 entries are not supported");
    entries_.push_back(std::move(e));
    at += 46 + name_len + extra + comment;
  }
}

std::vector<std::string> ZipReader::names() const {
  std::vector<std::string> out;
  for (const Entry& e : entries_) out.push_back(e.name);
  return out;
}

bool ZipReader::contains(std::string_view entry) const {
  return std::any_of(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.name == entry; });
}

std::optional<std::string> ZipReader::read(std::string_view entry, std::size_t max_size) const {
  const auto it =
      std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.name == entry; });
  if (it == entries_.end()) return std::nullopt;
  const Entry& e = *it;
  const std::string where = name_ + ":" + e.name;
  const auto bad = [&](std::size_t at, const std::string& why) {
    return InputError(where, InputLocation::at_byte(at), why);
  };
  if (e.size > max_size)
    throw bad(e.local_offset, "is " + std::to_string(e.size) + " bytes inflated, more than the " +
                                  std::to_string(max_size) + " allowed");
  if (e.flags & 1u) throw bad(e.local_offset, "is encrypted");
  const std::size_t at = e.local_offset;
  if (std::uint64_t{at} + 30 > archive_.size() || get32(archive_, at) != local_signature)
    throw bad(at, "no local header where the directory says (truncated?)");
  const std::size_t data = at + 30 + get16(archive_, at + 26) + get16(archive_, at + 28);
  if (std::uint64_t{data} + e.compressed > archive_.size())
    throw bad(data, "data runs past the end of the archive (truncated)");
  const std::string_view raw = archive_.substr(data, e.compressed);
  std::string out;
  if (e.method == 0) {
    if (e.compressed != e.size) throw bad(data, "stored entry whose sizes disagree");
    out = std::string(raw);
  } else if (e.method == 8) {
    out = inflate_raw(raw, e.size, max_size, where);
  } else {
    throw bad(
        at, "compression method " + std::to_string(e.method) + " is not supported (only stored and deflate)");
  }
  const auto crc = static_cast<std::uint32_t>(
      crc32(0L, reinterpret_cast<const Bytef*>(out.data()), static_cast<uInt>(out.size())));
  if (crc != e.crc) throw bad(data, "CRC-32 mismatch (corrupt archive)");
  return out;
}

}  // namespace salient::core
