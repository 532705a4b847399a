// A small owned 16-bit image for the image-processing tests.
#pragma once

#include <cstdint>
#include <vector>

#include "recon/scan/stripe.hpp"  // ImageView

namespace bodyscan::testing {

struct Image {
  int w, h;
  std::vector<uint16_t> px;
  ImageView view() const { return {px.data(), w, h}; }
};

}  // namespace bodyscan::testing
