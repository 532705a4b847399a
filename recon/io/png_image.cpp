#include "recon/io/png_image.hpp"

#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <iterator>

#include "recon/io/atomic_file.hpp"

namespace bodyscan {

namespace {

void append_bytes(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::string*>(png_get_io_ptr(png));
  out->append(reinterpret_cast<const char*>(data), length);
}
void no_flush(png_structp) {}

struct Reader {
  const std::string* bytes;
  size_t offset = 0;
};
void read_bytes(png_structp png, png_bytep data, png_size_t length) {
  auto* r = static_cast<Reader*>(png_get_io_ptr(png));
  if (r->offset + length > r->bytes->size()) png_error(png, "the file ends early");
  std::memcpy(data, r->bytes->data() + r->offset, length);
  r->offset += length;
}
// libpng reports errors through longjmp; keep its message for ours.
void on_error(png_structp png, png_const_charp message) {
  auto* text = static_cast<std::string*>(png_get_error_ptr(png));
  if (text) *text = message;
  png_longjmp(png, 1);
}
void on_warning(png_structp, png_const_charp) {}

// libpng's longjmp returns to the setjmp below it, which C++ allows only when no
// object with a non-trivial destructor lies in between ([csetjmp.syn]), and after
// which C leaves indeterminate every non-volatile local of the setjmp's function
// that changed since the setjmp. So each libpng session runs in a function of its
// own whose locals are trivial and are not read after a jump: what it fills lives
// in the caller's frame, reached through pointers. Each returns false after a
// libpng error (its message where png_get_error_ptr points).

bool encode_rows(png_structp png, png_infop info, const GrayImage& image, int compression, std::string* bytes,
                 std::vector<uint8_t>* row) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_write_fn(png, bytes, append_bytes, no_flush);
  png_set_compression_level(png, compression);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width), static_cast<png_uint_32>(image.height),
               image.bit_depth, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  uint8_t* out = row->data();
  for (int y = 0; y < image.height; ++y) {
    const uint16_t* src = image.pixels.data() + static_cast<size_t>(y) * image.width;
    for (int x = 0; x < image.width; ++x) {
      if (image.bit_depth == 8) {
        out[x] = static_cast<uint8_t>(std::min<uint16_t>(src[x], 255));
      } else {
        out[2 * x] = static_cast<uint8_t>(src[x] >> 8);  // PNG is big-endian
        out[2 * x + 1] = static_cast<uint8_t>(src[x] & 0xff);
      }
    }
    png_write_row(png, out);
  }
  png_write_end(png, nullptr);
  return true;
}

// Reads the header into *image (size and depth) and, when it is an 8- or 16-bit
// grayscale image, the pixels; *gray says which.
bool decode_rows(png_structp png, png_infop info, Reader* reader, GrayImage* image, std::vector<uint8_t>* row,
                 bool* gray) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_read_fn(png, reader, read_bytes);
  png_set_user_limits(png, 20000, 20000);  // refuse absurd sizes before allocating
  png_read_info(png, info);
  const int color = png_get_color_type(png, info);
  const int depth = png_get_bit_depth(png, info);
  *gray = color == PNG_COLOR_TYPE_GRAY && (depth == 8 || depth == 16);
  if (!*gray) return true;
  image->width = static_cast<int>(png_get_image_width(png, info));
  image->height = static_cast<int>(png_get_image_height(png, info));
  image->bit_depth = depth;
  image->pixels.resize(static_cast<size_t>(image->width) * image->height);
  row->resize(png_get_rowbytes(png, info));
  for (int y = 0; y < image->height; ++y) {
    png_read_row(png, row->data(), nullptr);
    uint16_t* dst = image->pixels.data() + static_cast<size_t>(y) * image->width;
    const uint8_t* in = row->data();
    for (int x = 0; x < image->width; ++x)
      dst[x] = depth == 8 ? in[x] : static_cast<uint16_t>(in[2 * x] << 8 | in[2 * x + 1]);
  }
  png_read_end(png, nullptr);
  return true;
}

}  // namespace

Status write_png(const std::string& path, const GrayImage& image, int compression) {
  StatusOr<std::string> bytes = encode_png(image, compression);
  if (!bytes.ok()) return Status(bytes.status().code(), path + ": not written: " + bytes.status().message());
  return write_file_atomically(path, *bytes);
}

StatusOr<std::string> encode_png(const GrayImage& image, int compression) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<size_t>(image.width) * static_cast<size_t>(image.height)) {
    return invalid_argument("the image's size does not match its pixels");
  }
  if (image.bit_depth != 8 && image.bit_depth != 16) return invalid_argument("bit depth must be 8 or 16");
  std::string bytes, error;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, on_error, on_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    return internal_error("libpng could not start");
  }
  std::vector<uint8_t> row(static_cast<size_t>(image.width) * (image.bit_depth / 8));
  const bool ok = encode_rows(png, info, image, compression, &bytes, &row);
  png_destroy_write_struct(&png, &info);
  if (!ok) return internal_error("PNG encoding failed: " + error);
  return bytes;
}

StatusOr<GrayImage> read_png(const std::string& path) {
  ASSIGN_OR_RETURN(const std::string bytes, read_whole_file(path));
  if (bytes.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) != 0) {
    return invalid_argument(path + ": not a PNG file");
  }
  std::string error;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &error, on_error, on_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_read_struct(&png, &info, nullptr);
    return internal_error(path + ": libpng could not start");
  }
  GrayImage image;
  std::vector<uint8_t> row;
  Reader reader{&bytes};
  bool gray = false;
  const bool ok = decode_rows(png, info, &reader, &image, &row, &gray);
  png_destroy_read_struct(&png, &info, nullptr);
  if (!ok) return invalid_argument(path + ": corrupt PNG: " + error);
  if (!gray) return invalid_argument(path + ": only 8- and 16-bit grayscale PNG images are read here");
  return image;
}

}  // namespace bodyscan
