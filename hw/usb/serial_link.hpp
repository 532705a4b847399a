// A serial port as a ByteLink: a USB CDC-ACM board's device node (/dev/ttyACM0,
// /dev/serial/by-id/...) or, in tests, the slave side of a pseudo-terminal.
#pragma once

#include <memory>

#include "hw/usb/byte_link.hpp"

namespace bodyscan::hw::usb {

class SerialLink : public ByteLink {
 public:
  // Opens the port raw (no echo, no line discipline), 8N1 at `baud`. For a USB
  // CDC-ACM board the baud rate is ignored by the device but harmless.
  static StatusOr<std::unique_ptr<SerialLink>> open(const std::string& path, int baud = 115200);
  ~SerialLink() override;

  Status write(const uint8_t* data, size_t size, std::chrono::milliseconds timeout) override;
  Status read(uint8_t* data, size_t size, std::chrono::milliseconds timeout) override;
  void discard_input() override;
  bool emergency_write(const uint8_t* data, size_t size) noexcept override;
  const std::string& name() const override { return path_; }

 private:
  SerialLink(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
  Status gone(const char* what, int err) const;
  int fd_ = -1;
  std::string path_;
};

}  // namespace bodyscan::hw::usb
