// 3MF export: a valid ZIP with the four parts, and PrusaSlicer's step profile for a plan.
#include "core/export/three_mf.hpp"

#include <doctest/doctest.h>
#include <zlib.h>

#include <cstring>

#include "core/export/zip_writer.hpp"
#include "tests/core/mesh/mesh_test_util.hpp"

using namespace salient::core;

namespace {

std::uint32_t read32(const std::string& s, std::size_t at) {
  std::uint32_t v;
  std::memcpy(&v, s.data() + at, 4);
  return v;
}
std::uint16_t read16(const std::string& s, std::size_t at) {
  std::uint16_t v;
  std::memcpy(&v, s.data() + at, 2);
  return v;
}

}  // namespace

TEST_CASE("ZIP: local entries, central directory and end record agree") {
  ZipWriter zip;
  zip.add("a.txt", "hello");
  zip.add("dir/b.txt", "world!");
  const std::string z = zip.finish();
  const std::size_t end = z.size() - 22;
  REQUIRE(read32(z, end) == 0x06054b50);
  CHECK(read16(z, end + 10) == 2);
  const std::uint32_t dir = read32(z, end + 16);
  REQUIRE(read32(z, dir) == 0x02014b50);
  CHECK(read32(z, 0) == 0x04034b50);
  CHECK(read32(z, 14) == crc32(0L, reinterpret_cast<const Bytef*>("hello"), 5));
  CHECK(z.substr(30, 5) == "a.txt");
  CHECK(z.substr(35, 5) == "hello");
}

TEST_CASE("PrusaSlicer profile: two points a layer make a step function") {
  CHECK(prusa_layer_height_profile({0, 0.2, 0.3, 0.7}) ==
        "object_id=1|0.000000;0.200000;0.199900;0.200000;0.200000;0.100000;0.299900;0.100000;0.300000;0."
        "400000;0.700000;"
        "0.400000\n");
}

TEST_CASE("3MF holds the model, the relationships and the profile") {
  const std::string bytes = three_mf(salient::test::box(1, 2, 3), {0, 1.5, 3}, "box <1>");
  for (const char* part : {"[Content_Types].xml", "_rels/.rels", "3D/3dmodel.model",
                           "Metadata/Slic3r_PE_layer_heights_profile.txt"})
    CHECK(bytes.find(part) != std::string::npos);
  CHECK(bytes.find("name=\"box &lt;1&gt;\"") != std::string::npos);
  CHECK(bytes.find("<vertex x=\"1.000000\" y=\"2.000000\" z=\"3.000000\"/>") != std::string::npos);
  CHECK(bytes.find("<triangle v1=\"0\" v2=\"2\" v3=\"1\"/>") != std::string::npos);
}
