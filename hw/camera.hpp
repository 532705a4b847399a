// The camera interface every backend implements: the simulated rig (hw/sim), and
// GenICam cameras through Aravis (a later backend). Calibration and scanning use
// only this.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "core/status.hpp"
#include "hw/rig_description.hpp"

namespace bodyscan::hw {

// One grabbed image. Pixels are row-major, width * height, always 16-bit in memory
// with the sensor's value in the low `bits_per_pixel(format)` bits (Mono8 frames
// hold 0..255), so every later stage handles one layout.
struct Frame {
  int width = 0, height = 0;
  PixelFormat format = PixelFormat::kMono8;
  std::vector<uint16_t> pixels;
  uint64_t frame_id = 0;     // per camera, counting from 1
  int64_t timestamp_ns = 0;  // the camera's clock (the simulator's scene time)
  double exposure_us = 0, gain_db = 0;

  uint16_t at(int x, int y) const { return pixels[static_cast<size_t>(y) * width + x]; }
  int max_value() const { return (1 << bits_per_pixel(format)) - 1; }
};

struct CameraInfo {
  std::string id;  // the rig description's id
  std::string vendor, model, serial;
  int width = 0, height = 0;
  std::vector<PixelFormat> formats;
};

class Camera {
 public:
  virtual ~Camera() = default;
  virtual const CameraInfo& info() const = 0;

  virtual Status set_pixel_format(PixelFormat format) = 0;
  virtual Status set_exposure_us(double exposure) = 0;
  virtual Status set_gain_db(double gain) = 0;
  virtual PixelFormat pixel_format() const = 0;
  virtual double exposure_us() const = 0;
  virtual double gain_db() const = 0;

  // Software trigger: exposes one frame now and returns it. Errors: deadline_exceeded
  // when no frame arrives within `timeout`, unavailable when the camera is gone;
  // the message names the camera.
  virtual StatusOr<Frame> grab(std::chrono::milliseconds timeout = std::chrono::milliseconds(2000)) = 0;
};

}  // namespace bodyscan::hw
