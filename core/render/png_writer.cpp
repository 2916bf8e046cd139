// write_png, png_bytes and decode_png through libpng (the one file that includes it).
#include <png.h>

#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "core/common/input_error.hpp"
#include "core/render/image.hpp"

namespace salient::core {
namespace {

// Encodes through libpng's write callback into `out`; returns false if libpng failed.
bool encode(const Image& image, std::string& out) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(
      png, &out,
      [](png_structp p, png_bytep data, png_size_t size) {
        static_cast<std::string*>(png_get_io_ptr(p))->append(reinterpret_cast<const char*>(data), size);
      },
      nullptr);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < image.height; ++y)
    png_write_row(png, image.rgb.data() + static_cast<std::size_t>(y) * image.width * 3);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

struct ReadCursor {
  std::string_view bytes;
  std::size_t at = 0;
};

}  // namespace

std::string png_bytes(const Image& image) {
  std::string out;
  if (!encode(image, out)) throw InputError("image", {}, "PNG encoding failed");
  return out;
}

void write_png(const std::filesystem::path& path, const Image& image) {
  const std::string name = path.filename().string();
  const std::string bytes = png_bytes(image);
  std::unique_ptr<FILE, int (*)(FILE*)> file(std::fopen(path.c_str(), "wb"), &std::fclose);
  if (!file || std::fwrite(bytes.data(), 1, bytes.size(), file.get()) != bytes.size())
    throw InputError(name, {}, "cannot write");
}

Image decode_png(std::string_view bytes, const std::string& source) {
  if (bytes.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) != 0)
    throw InputError(source, {}, "is not a PNG (bad signature)");
  // Errors become the InputError below, not a line on stderr.
  png_structp png = png_create_read_struct(
      PNG_LIBPNG_VER_STRING, nullptr, [](png_structp p, png_const_charp) { png_longjmp(p, 1); },
      [](png_structp, png_const_charp) {});
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  ReadCursor cursor{bytes};
  // Declared before setjmp, so a longjmp out of libpng leaves them in scope to be destroyed.
  Image image(0, 0);
  std::vector<png_bytep> rows;
  if (!png || !info || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw InputError(source, {}, "is not a valid PNG");
  }
  png_set_read_fn(png, &cursor, [](png_structp p, png_bytep data, png_size_t size) {
    auto* c = static_cast<ReadCursor*>(png_get_io_ptr(p));
    if (size > c->bytes.size() - c->at) png_error(p, "truncated");
    std::memcpy(data, c->bytes.data() + c->at, size);
    c->at += size;
  });
  png_read_info(png, info);
  // Normalise every colour type to 8-bit RGB.
  png_set_strip_16(png);
  png_set_strip_alpha(png);
  png_set_packing(png);
  png_set_palette_to_rgb(png);
  png_set_expand_gray_1_2_4_to_8(png);
  png_set_gray_to_rgb(png);
  png_read_update_info(png, info);
  const int w = static_cast<int>(png_get_image_width(png, info)),
            h = static_cast<int>(png_get_image_height(png, info));
  image = Image(w, h);
  rows.resize(static_cast<std::size_t>(h));
  for (int y = 0; y < h; ++y) rows[y] = image.at(0, y);
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return image;
}

}  // namespace salient::core
