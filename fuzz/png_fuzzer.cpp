// PNG files, through the reader the archive and the camera records use. libpng
// reads from a file, so each input is written to one first (in the fuzzer's
// working folder, overwritten every run).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "recon/io/png_image.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = "png_fuzzer_input." + std::to_string(::getpid()) + ".png";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  const bool written = std::fwrite(data, 1, size, f) == size;
  std::fclose(f);
  if (!written) return 0;
  auto image = bodyscan::read_png(path);
  if (image.ok() && image->pixels.size() != static_cast<size_t>(image->width) * image->height) __builtin_trap();
  return 0;
}
