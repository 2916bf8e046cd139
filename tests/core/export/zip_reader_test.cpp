// ZipReader: what ZipWriter and zlib's deflate write reads back; a truncated archive, a wrong
// CRC, a lying directory and a zip bomb are refused with the file named.
#include "core/export/zip_reader.hpp"

#include <doctest/doctest.h>
#include <zlib.h>

#include <random>

#include "core/common/input_error.hpp"
#include "core/export/zip_writer.hpp"

using namespace salient::core;

namespace {

void put16(std::string& out, std::uint32_t v) {
  out.push_back(static_cast<char>(v & 0xff));
  out.push_back(static_cast<char>((v >> 8) & 0xff));
}
void put32(std::string& out, std::uint32_t v) {
  put16(out, v & 0xffff);
  put16(out, v >> 16);
}

std::string raw_deflate(const std::string& data) {
  z_stream z{};
  REQUIRE(deflateInit2(&z, 9, Z_DEFLATED, -MAX_WBITS, 8, Z_DEFAULT_STRATEGY) == Z_OK);
  std::string out(deflateBound(&z, data.size()), '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  z.avail_in = static_cast<uInt>(data.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  REQUIRE(deflate(&z, Z_FINISH) == Z_STREAM_END);
  out.resize(out.size() - z.avail_out);
  deflateEnd(&z);
  return out;
}

// A one-entry archive with a deflated entry (as PrusaSlicer's 3MFs are); `size` and `crc` as the
// directory should say them unless overridden.
std::string deflated_zip(const std::string& name, const std::string& data,
                         std::optional<std::uint32_t> size = {}, std::optional<std::uint32_t> crc = {}) {
  const std::string packed = raw_deflate(data);
  const auto real_crc = static_cast<std::uint32_t>(
      crc32(0L, reinterpret_cast<const Bytef*>(data.data()), static_cast<uInt>(data.size())));
  const std::uint32_t c = crc.value_or(real_crc), n = size.value_or(static_cast<std::uint32_t>(data.size()));
  std::string out;
  put32(out, 0x04034b50);
  for (std::uint32_t v : {20u, 0u, 8u, 0u, 0u}) put16(out, v);
  put32(out, c);
  put32(out, static_cast<std::uint32_t>(packed.size()));
  put32(out, n);
  put16(out, static_cast<std::uint32_t>(name.size()));
  put16(out, 0);
  out += name + packed;
  const auto dir_offset = static_cast<std::uint32_t>(out.size());
  put32(out, 0x02014b50);
  for (std::uint32_t v : {20u, 20u, 0u, 8u, 0u, 0u}) put16(out, v);
  put32(out, c);
  put32(out, static_cast<std::uint32_t>(packed.size()));
  put32(out, n);
  put16(out, static_cast<std::uint32_t>(name.size()));
  for (int i = 0; i < 4; ++i) put16(out, 0);
  put32(out, 0);
  put32(out, 0);
  out += name;
  const auto dir_size = static_cast<std::uint32_t>(out.size()) - dir_offset;
  put32(out, 0x06054b50);
  put16(out, 0);
  put16(out, 0);
  put16(out, 1);
  put16(out, 1);
  put32(out, dir_size);
  put32(out, dir_offset);
  put16(out, 0);
  return out;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("ZIP reader: every entry ZipWriter stores reads back byte for byte") {
  std::mt19937 rng(7);
  ZipWriter zip;
  std::vector<std::pair<std::string, std::string>> entries;
  for (int i = 0; i < 12; ++i) {
    std::string data(rng() % 3000, '\0');
    for (char& c : data) c = static_cast<char>(rng());
    entries.emplace_back("dir/entry" + std::to_string(i), data);
    zip.add(entries.back().first, data);
  }
  const std::string archive = zip.finish();
  const ZipReader reader(archive, "t.zip");
  CHECK(reader.names().size() == entries.size());
  for (const auto& [name, data] : entries) CHECK(reader.read(name) == data);
  CHECK_FALSE(reader.read("no/such/entry").has_value());
  CHECK_FALSE(reader.contains("no/such/entry"));
}

TEST_CASE("ZIP reader: a deflated entry inflates to its data") {
  std::string text;
  for (int i = 0; i < 2000; ++i) text += "0.1;0.2;" + std::to_string(i) + "\n";
  const std::string archive = deflated_zip("Metadata/x.txt", text);
  CHECK(archive.size() < text.size());
  CHECK(ZipReader(archive, "d.3mf").read("Metadata/x.txt") == text);
}

TEST_CASE("ZIP reader: every truncation of an archive is refused or reads correctly, never crashes") {
  ZipWriter zip;
  zip.add("a.txt", std::string(500, 'a'));
  zip.add("b.txt", std::string(300, 'b'));
  const std::string archive = zip.finish();
  for (std::size_t n = 0; n < archive.size(); ++n) {
    const std::string cut = archive.substr(0, n);
    const std::string e = error_of([&] {
      const ZipReader r(cut, "cut.zip");
      for (const std::string& name : r.names()) (void)r.read(name);
    });
    CHECK_MESSAGE(e.starts_with("cut.zip"), n);  // the end record is last: any cut loses it
  }
  const std::string deflated = deflated_zip("x.txt", std::string(4000, 'x'));
  // Cut inside the deflate data but keep the directory: the data runs past its end.
  std::string holed = deflated;
  holed.erase(40, 5);
  CHECK(error_of([&] { (void)ZipReader(holed, "h.zip").read("x.txt"); }).starts_with("h.zip"));
}

TEST_CASE("ZIP reader: a wrong CRC-32 or a lying size is refused, naming the entry") {
  const std::string text(1000, 'q');
  CHECK(error_of([&] {
          (void)ZipReader(deflated_zip("e.txt", text, {}, 1234), "c.zip").read("e.txt");
        }).find("c.zip:e.txt: byte") == 0);
  CHECK(error_of([&] {
          (void)ZipReader(deflated_zip("e.txt", text, {}, 1234), "c.zip").read("e.txt");
        }).find("CRC-32 mismatch") != std::string::npos);
  CHECK(error_of([&] {
          (void)ZipReader(deflated_zip("e.txt", text, 10), "s.zip").read("e.txt");
        }).find("more than the 10 bytes its directory says") != std::string::npos);
  CHECK(error_of([&] {
          (void)ZipReader(deflated_zip("e.txt", text, 5000), "s.zip").read("e.txt");
        }).find("inflates to 1000 bytes, its directory says 5000") != std::string::npos);
}

TEST_CASE("ZIP reader: a zip bomb is refused before it is inflated past the bound") {
  const std::string huge(8u << 20, '\0');  // 8 MiB of zeros deflate to a few KiB
  const std::string archive = deflated_zip("bomb.txt", huge);
  CHECK(archive.size() < 64 * 1024);
  const ZipReader reader(archive, "bomb.3mf");
  CHECK(error_of([&] { (void)reader.read("bomb.txt", 1u << 20); }).find("more than the 1048576 allowed") !=
        std::string::npos);
  // A directory that understates the size: inflation stops one byte past what it claims.
  const std::string liar = deflated_zip("bomb.txt", huge, 100);
  CHECK(error_of([&] {
          (void)ZipReader(liar, "liar.3mf").read("bomb.txt", 1u << 20);
        }).find("more than the 100 bytes its directory says") != std::string::npos);
  CHECK(reader.read("bomb.txt", 16u << 20)->size() == huge.size());
}

TEST_CASE("ZIP reader: not an archive") {
  CHECK(error_of([] { ZipReader("", "e.zip"); }).find("not a ZIP archive") != std::string::npos);
  CHECK(error_of([] { ZipReader(std::string(100, 'z'), "z.zip"); }).find("no end record") !=
        std::string::npos);
}
