// GenICam (PFNC) monochrome pixel layouts to the Frame's one layout: 16-bit values
// with the sensor's value in the low bits. Kept apart from Aravis so it is tested
// byte for byte without a camera.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/status.hpp"

namespace bodyscan::hw::aravis {

// PFNC codes (the same numbers Aravis' ARV_PIXEL_FORMAT_* use).
enum PfncMono : uint32_t {
  kPfncMono8 = 0x01080001u,
  kPfncMono10 = 0x01100003u,
  kPfncMono10Packed = 0x010c0004u,  // GigE Vision packing: 2 pixels in 3 bytes, high bits first
  kPfncMono12 = 0x01100005u,
  kPfncMono12Packed = 0x010c0006u,  // GigE Vision packing
  kPfncMono16 = 0x01100007u,
  kPfncMono10p = 0x010a0046u,  // PFNC LSB-first bit stream
  kPfncMono12p = 0x010c0047u,  // PFNC LSB-first bit stream
};

const char* pfnc_name(uint32_t code);  // "Mono12Packed"; "" for others
int pfnc_bits(uint32_t code);          // significant bits; 0 for a format not handled here

// Unpacks a width x height image of `code` from `data` into `out` (resized).
// invalid_argument for a format that is not monochrome, or too few bytes.
Status unpack_mono(uint32_t code, const uint8_t* data, size_t size, int width, int height, std::vector<uint16_t>& out);

}  // namespace bodyscan::hw::aravis
