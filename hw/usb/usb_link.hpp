// A USB CDC-ACM board (a virtual serial port: TMCL modules, most USB stepper and
// relay boards) driven directly through libusb, without the kernel's tty: the
// data interface's bulk endpoints carry the bytes. Used when the rig description
// gives the board's USB ids rather than a serial port.
//
// The device node is opened by this class and handed to libusb
// (libusb_wrap_sys_device), so the signal path can reach the board with one usbfs
// ioctl on the same, already claimed, file descriptor.
#pragma once

#include <libusb.h>

#include <memory>
#include <vector>

#include "hw/usb/byte_link.hpp"

namespace bodyscan::hw::usb {

struct UsbDeviceInfo {
  uint16_t vendor = 0, product = 0;
  int bus = 0, address = 0;
  std::string manufacturer, product_name, serial;  // empty when the device cannot be opened
  std::string known_as;                            // "TMCL module (Trinamic)" for the boards this project drives
};

// Every USB device on the machine, with the ones bodyscan drives named.
StatusOr<std::vector<UsbDeviceInfo>> list_usb_devices();

class UsbLink : public ByteLink {
 public:
  // The first device with these ids (and this serial number, if given).
  static StatusOr<std::unique_ptr<UsbLink>> open(uint16_t vendor, uint16_t product, const std::string& serial);
  ~UsbLink() override;

  Status write(const uint8_t* data, size_t size, std::chrono::milliseconds timeout) override;
  Status read(uint8_t* data, size_t size, std::chrono::milliseconds timeout) override;
  void discard_input() override;
  bool emergency_write(const uint8_t* data, size_t size) noexcept override;
  const std::string& name() const override { return name_; }

 private:
  UsbLink() = default;
  Status error(const char* what, int code) const;
  libusb_context* ctx_ = nullptr;
  libusb_device_handle* handle_ = nullptr;
  int fd_ = -1;
  int comm_interface_ = -1, data_interface_ = -1;
  uint8_t in_ep_ = 0, out_ep_ = 0;
  int in_packet_ = 64;
  std::vector<uint8_t> rx_;
  std::string name_;
};

}  // namespace bodyscan::hw::usb
