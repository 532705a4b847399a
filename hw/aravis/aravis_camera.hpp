// GenICam cameras - GigE Vision and USB3 Vision - through Aravis, behind the same
// Camera interface as the simulated rig. docs/hardware.md lists what was tested.
//
// A camera is opened by the id `bodyscan devices` prints (Aravis' "vendor-model-
// serial" id) or by its IP address. Frames are triggered in software (grab()
// fires the trigger and waits) or by a hardware line (grab() waits for the next
// frame the line starts). Mono8, Mono10/12/16 and their packed layouts arrive as
// the Frame's 16-bit pixels.
//
// Errors name the camera and say what to check: a frame that does not come
// (deadline_exceeded), a frame with lost packets (data_loss as io_error, after one
// retry), a camera unplugged or powered off (unavailable, from Aravis' control-lost
// signal or the stream).
#pragma once

#include <memory>
#include <mutex>
#include <vector>

#include "hw/camera.hpp"

namespace bodyscan::hw::aravis {

struct AravisDeviceInfo {
  std::string id, vendor, model, serial, protocol, address;
};

// Cameras Aravis finds (GigE Vision on every interface, USB3 Vision). With
// `include_fake`, also Aravis' in-process fake camera ("Fake_1"), for tests.
std::vector<AravisDeviceInfo> list_cameras(bool include_fake = false);

class AravisCamera : public Camera {
 public:
  // Opens `device.id` and sets it up as `desc` says: pixel format, exposure, gain,
  // trigger, packet size. The CameraInfo's id is desc.id (the rig's name for it).
  static StatusOr<std::unique_ptr<AravisCamera>> open(const CameraDescription& desc);
  ~AravisCamera() override;

  const CameraInfo& info() const override { return info_; }
  Status set_pixel_format(PixelFormat format) override;
  Status set_exposure_us(double exposure) override;
  Status set_gain_db(double gain) override;
  PixelFormat pixel_format() const override { return format_; }
  double exposure_us() const override { return exposure_us_; }
  double gain_db() const override { return gain_db_; }
  StatusOr<Frame> grab(std::chrono::milliseconds timeout) override;

  // Stream counters since open: frames completed, frames lost or incomplete.
  struct Statistics {
    uint64_t completed = 0, failures = 0, underruns = 0;
  };
  Statistics statistics() const;
  // The device behind it (ArvDevice*), for tests that drive Aravis' fake camera.
  void* device() const;

 private:
  struct Impl;
  explicit AravisCamera(std::unique_ptr<Impl> impl);
  Status restart_stream();
  std::unique_ptr<Impl> impl_;
  CameraInfo info_;
  PixelFormat format_ = PixelFormat::kMono8;
  double exposure_us_ = 0, gain_db_ = 0;
  mutable std::mutex mutex_;
};

}  // namespace bodyscan::hw::aravis
