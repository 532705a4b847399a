#include "hw/aravis/pixel_unpack.hpp"

#include <cstdio>
#include <cstring>
#include <string>

namespace bodyscan::hw::aravis {

const char* pfnc_name(uint32_t code) {
  switch (code) {
    case kPfncMono8: return "Mono8";
    case kPfncMono10: return "Mono10";
    case kPfncMono10Packed: return "Mono10Packed";
    case kPfncMono12: return "Mono12";
    case kPfncMono12Packed: return "Mono12Packed";
    case kPfncMono16: return "Mono16";
    case kPfncMono10p: return "Mono10p";
    case kPfncMono12p: return "Mono12p";
    default: return "";
  }
}

int pfnc_bits(uint32_t code) {
  switch (code) {
    case kPfncMono8: return 8;
    case kPfncMono10:
    case kPfncMono10Packed:
    case kPfncMono10p: return 10;
    case kPfncMono12:
    case kPfncMono12Packed:
    case kPfncMono12p: return 12;
    case kPfncMono16: return 16;
    default: return 0;
  }
}

Status unpack_mono(uint32_t code, const uint8_t* data, size_t size, int width, int height, std::vector<uint16_t>& out) {
  if (width <= 0 || height <= 0)
    return invalid_argument("an image of " + std::to_string(width) + " x " + std::to_string(height));
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  const int bits = pfnc_bits(code);
  if (bits == 0) {
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%08x", code);
    return invalid_argument(std::string("pixel format ") + hex +
                            " is not a monochrome format bodyscan reads (Mono8, Mono10/12/16 and their packed forms)");
  }
  const size_t container = (code >> 16) & 0xff;  // bits per pixel in the buffer
  // Packed rows are not padded in these formats; a frame is the whole bit stream.
  const size_t need = (n * container + 7) / 8;
  if (size < need) {
    return invalid_argument("a " + std::string(pfnc_name(code)) + " frame of " + std::to_string(width) + " x " +
                            std::to_string(height) + " needs " + std::to_string(need) + " bytes, got " +
                            std::to_string(size));
  }
  out.resize(n);
  switch (code) {
    case kPfncMono8:
      for (size_t i = 0; i < n; ++i) out[i] = data[i];
      break;
    case kPfncMono10:
    case kPfncMono12:
    case kPfncMono16: {
      const uint16_t mask = static_cast<uint16_t>((1u << bits) - 1u);
      for (size_t i = 0; i < n; ++i) out[i] = static_cast<uint16_t>((data[2 * i] | (data[2 * i + 1] << 8)) & mask);
      break;
    }
    case kPfncMono10Packed:
    case kPfncMono12Packed: {
      // Per pair: byte 0 = p0's high 8 bits, byte 2 = p1's high 8 bits, byte 1 holds
      // the low bits: p0's in bits 0.., p1's in bits 4..
      const int low = bits - 8;
      const unsigned low_mask = (1u << low) - 1u;
      for (size_t i = 0; i < n; i += 2) {
        const uint8_t* b = data + (i / 2) * 3;
        out[i] = static_cast<uint16_t>((b[0] << low) | (b[1] & low_mask));
        if (i + 1 < n) out[i + 1] = static_cast<uint16_t>((b[2] << low) | ((b[1] >> 4) & low_mask));
      }
      break;
    }
    case kPfncMono10p:
    case kPfncMono12p: {
      // A little-endian bit stream: pixel i occupies bits [i*bits, (i+1)*bits).
      const unsigned mask = (1u << bits) - 1u;
      for (size_t i = 0; i < n; ++i) {
        const size_t bit = i * static_cast<size_t>(bits);
        const size_t byte = bit / 8;
        uint32_t word = data[byte];
        if (byte + 1 < size) word |= static_cast<uint32_t>(data[byte + 1]) << 8;
        if (byte + 2 < size) word |= static_cast<uint32_t>(data[byte + 2]) << 16;
        out[i] = static_cast<uint16_t>((word >> (bit % 8)) & mask);
      }
      break;
    }
    default: break;
  }
  return Status::Ok();
}

}  // namespace bodyscan::hw::aravis
