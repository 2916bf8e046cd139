// Image: 8-bit RGB pixels, and writing it as PNG.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace salient::core {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  // row-major, 3 bytes a pixel

  Image(int w, int h, std::uint8_t fill = 255)
      : width(w), height(h), rgb(static_cast<std::size_t>(w) * h * 3, fill) {}
  std::uint8_t* at(int x, int y) { return rgb.data() + (static_cast<std::size_t>(y) * width + x) * 3; }
};

// Throws InputError if the file cannot be written.
void write_png(const std::filesystem::path& path, const Image& image);

// The PNG file's bytes, for embedding (a G-code thumbnail, an API response).
std::string png_bytes(const Image& image);

// Decodes a PNG (any bit depth or colour type, alpha dropped) to RGB. Throws InputError naming
// `source` if the bytes are not a valid PNG: what a reader of our thumbnails would see.
Image decode_png(std::string_view bytes, const std::string& source);

}  // namespace salient::core
