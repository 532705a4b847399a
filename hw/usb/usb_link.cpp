#include "hw/usb/usb_link.hpp"

#include <fcntl.h>
#include <linux/usbdevice_fs.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace bodyscan::hw::usb {

namespace {

std::string hex4(uint16_t v) {
  char b[8];
  std::snprintf(b, sizeof b, "%04x", v);
  return b;
}

std::string known_board(uint16_t vendor, uint16_t product) {
  if (vendor == 0x2a3c && (product == 0x0100 || product == 0x0200 || product == 0x0700))
    return "TMCL module (Trinamic)";
  if (vendor == 0x16d0 && (product == 0x0461 || product == 0x05a1 || product == 0x07e4))
    return "TMCL module (Trinamic)";
  return "";
}

std::string string_descriptor(libusb_device_handle* h, uint8_t index) {
  if (index == 0) return "";
  unsigned char buf[256];
  const int n = libusb_get_string_descriptor_ascii(h, index, buf, sizeof buf);
  return n > 0 ? std::string(reinterpret_cast<char*>(buf), static_cast<size_t>(n)) : "";
}

struct Context {
  libusb_context* ctx = nullptr;
  ~Context() {
    if (ctx) libusb_exit(ctx);
  }
};

}  // namespace

StatusOr<std::vector<UsbDeviceInfo>> list_usb_devices() {
  Context c;
  if (int rc = libusb_init(&c.ctx); rc != 0) return unavailable(std::string("libusb: ") + libusb_strerror(rc));
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(c.ctx, &list);
  if (n < 0)
    return unavailable(std::string("libusb: cannot list USB devices: ") + libusb_strerror(static_cast<int>(n)));
  std::vector<UsbDeviceInfo> out;
  for (ssize_t i = 0; i < n; ++i) {
    libusb_device_descriptor d{};
    if (libusb_get_device_descriptor(list[i], &d) != 0) continue;
    UsbDeviceInfo info;
    info.vendor = d.idVendor;
    info.product = d.idProduct;
    info.bus = libusb_get_bus_number(list[i]);
    info.address = libusb_get_device_address(list[i]);
    info.known_as = known_board(d.idVendor, d.idProduct);
    libusb_device_handle* h = nullptr;
    if (libusb_open(list[i], &h) == 0) {
      info.manufacturer = string_descriptor(h, d.iManufacturer);
      info.product_name = string_descriptor(h, d.iProduct);
      info.serial = string_descriptor(h, d.iSerialNumber);
      libusb_close(h);
    }
    out.push_back(std::move(info));
  }
  libusb_free_device_list(list, 1);
  return out;
}

Status UsbLink::error(const char* what, int code) const {
  if (code == LIBUSB_ERROR_NO_DEVICE || code == LIBUSB_ERROR_IO || code == LIBUSB_ERROR_PIPE) {
    return unavailable("the controller " + name_ + " is gone (" + what + ": " + libusb_strerror(code) +
                       "): is it still plugged in and powered?");
  }
  if (code == LIBUSB_ERROR_TIMEOUT)
    return deadline_exceeded("the controller " + name_ + " did not answer (" + what + ")");
  return io_error("the controller " + name_ + ": " + what + ": " + libusb_strerror(code));
}

StatusOr<std::unique_ptr<UsbLink>> UsbLink::open(uint16_t vendor, uint16_t product, const std::string& serial) {
  std::unique_ptr<UsbLink> link(new UsbLink());
  const std::string ids = hex4(vendor) + ":" + hex4(product);
  if (int rc = libusb_init(&link->ctx_); rc != 0) return unavailable(std::string("libusb: ") + libusb_strerror(rc));
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(link->ctx_, &list);
  if (n < 0) return unavailable("libusb: cannot list USB devices");
  int bus = -1, address = -1;
  for (ssize_t i = 0; i < n && bus < 0; ++i) {
    libusb_device_descriptor d{};
    if (libusb_get_device_descriptor(list[i], &d) != 0 || d.idVendor != vendor || d.idProduct != product) continue;
    if (!serial.empty()) {
      libusb_device_handle* h = nullptr;
      if (libusb_open(list[i], &h) != 0) continue;
      const std::string s = string_descriptor(h, d.iSerialNumber);
      libusb_close(h);
      if (s != serial) continue;
    }
    bus = libusb_get_bus_number(list[i]);
    address = libusb_get_device_address(list[i]);
  }
  libusb_free_device_list(list, 1);
  if (bus < 0) {
    return unavailable("no USB device " + ids + (serial.empty() ? "" : " with serial number " + serial) +
                       " is connected: check the cable and the board's power (`bodyscan devices` lists what is there)");
  }
  char node[64];
  std::snprintf(node, sizeof node, "/dev/bus/usb/%03d/%03d", bus, address);
  link->name_ = "USB " + ids + " on bus " + std::to_string(bus) + " device " + std::to_string(address);
  link->fd_ = ::open(node, O_RDWR | O_CLOEXEC);
  if (link->fd_ < 0) {
    const int err = errno;
    return unavailable("cannot open " + link->name_ + " (" + node + "): " + std::strerror(err) +
                       (err == EACCES ? " - install deploy/udev/60-bodyscan.rules and replug the board" : ""));
  }
  if (int rc = libusb_wrap_sys_device(link->ctx_, static_cast<intptr_t>(link->fd_), &link->handle_); rc != 0) {
    return link->error("wrap", rc);
  }
  libusb_config_descriptor* cfg = nullptr;
  if (int rc = libusb_get_active_config_descriptor(libusb_get_device(link->handle_), &cfg); rc != 0) {
    return link->error("reading its configuration", rc);
  }
  for (uint8_t i = 0; i < cfg->bNumInterfaces; ++i) {
    const libusb_interface_descriptor& alt = cfg->interface[i].altsetting[0];
    if (alt.bInterfaceClass == LIBUSB_CLASS_COMM && link->comm_interface_ < 0)
      link->comm_interface_ = alt.bInterfaceNumber;
    // CDC-ACM only: vendor bridges (FTDI, CP210x) frame their data differently and
    // are driven through their kernel serial driver ("port" in the description).
    if (alt.bInterfaceClass != LIBUSB_CLASS_DATA) continue;
    uint8_t in = 0, out = 0;
    int in_size = 64;
    for (uint8_t e = 0; e < alt.bNumEndpoints; ++e) {
      const libusb_endpoint_descriptor& ep = alt.endpoint[e];
      if ((ep.bmAttributes & 0x3) != LIBUSB_TRANSFER_TYPE_BULK) continue;
      if (ep.bEndpointAddress & LIBUSB_ENDPOINT_IN)
        in = ep.bEndpointAddress, in_size = ep.wMaxPacketSize;
      else
        out = ep.bEndpointAddress;
    }
    if (in && out && link->data_interface_ < 0) {
      link->data_interface_ = alt.bInterfaceNumber;
      link->in_ep_ = in;
      link->out_ep_ = out;
      link->in_packet_ = in_size > 0 ? in_size : 64;
    }
  }
  libusb_free_config_descriptor(cfg);
  if (link->data_interface_ < 0)
    return io_error(link->name_ +
                    " is not a USB CDC-ACM board; give its serial port (\"port\": \"/dev/ttyUSB0\") in the rig "
                    "description instead");
  libusb_set_auto_detach_kernel_driver(link->handle_, 1);  // cdc_acm lets go of it
  for (int iface : {link->comm_interface_, link->data_interface_}) {
    if (iface < 0) continue;
    if (int rc = libusb_claim_interface(link->handle_, iface); rc != 0) {
      return rc == LIBUSB_ERROR_BUSY ? unavailable(link->name_ + " is in use by another program")
                                     : link->error("claim", rc);
    }
  }
  if (link->comm_interface_ >= 0) {
    // CDC: 115200 8N1, then DTR and RTS raised (some firmware only talks then).
    unsigned char coding[7] = {0x00, 0xc2, 0x01, 0x00, 0, 0, 8};
    (void)libusb_control_transfer(link->handle_, 0x21, 0x20, 0, static_cast<uint16_t>(link->comm_interface_), coding,
                                  sizeof coding, 500);
    (void)libusb_control_transfer(link->handle_, 0x21, 0x22, 0x03, static_cast<uint16_t>(link->comm_interface_),
                                  nullptr, 0, 500);
  }
  link->discard_input();
  return link;
}

UsbLink::~UsbLink() {
  if (handle_) {
    for (int iface : {comm_interface_, data_interface_})
      if (iface >= 0) libusb_release_interface(handle_, iface);
    libusb_close(handle_);
  }
  if (ctx_) libusb_exit(ctx_);
  if (fd_ >= 0) ::close(fd_);
}

Status UsbLink::write(const uint8_t* data, size_t size, std::chrono::milliseconds timeout) {
  int sent = 0;
  int rc = 0;
  {
    // A frame of up to a packet's size crosses USB whole or not at all; the ledger
    // still counts what went, for a write of several packets cut short.
    WireLedger::Send send(ledger_);
    if (!send.open()) return unavailable("the controller " + name_ + " is taken by the emergency stop");
    rc = libusb_bulk_transfer(handle_, out_ep_, const_cast<uint8_t*>(data), static_cast<int>(size), &sent,
                              static_cast<unsigned>(timeout.count()));
    if (sent > 0) send.sent(data, static_cast<size_t>(sent));
  }
  if (rc != 0) return error("write", rc);
  if (static_cast<size_t>(sent) != size)
    return deadline_exceeded("the controller " + name_ + " took only part of a command");
  return Status::Ok();
}

Status UsbLink::read(uint8_t* data, size_t size, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::vector<uint8_t> packet(static_cast<size_t>(std::max(in_packet_, 64)));
  while (rx_.size() < size) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      return deadline_exceeded("the controller " + name_ + " did not answer within " + std::to_string(timeout.count()) +
                               " ms");
    }
    int got = 0;
    const int rc = libusb_bulk_transfer(handle_, in_ep_, packet.data(), static_cast<int>(packet.size()), &got,
                                        static_cast<unsigned>(left.count()));
    if (rc != 0 && rc != LIBUSB_ERROR_TIMEOUT) return error("read", rc);
    rx_.insert(rx_.end(), packet.begin(), packet.begin() + got);
  }
  std::copy(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(size), data);
  rx_.erase(rx_.begin(), rx_.begin() + static_cast<std::ptrdiff_t>(size));
  return Status::Ok();
}

void UsbLink::discard_input() {
  rx_.clear();
  std::vector<uint8_t> packet(static_cast<size_t>(std::max(in_packet_, 64)));
  int got = 0;
  for (int i = 0; i < 16; ++i) {
    if (libusb_bulk_transfer(handle_, in_ep_, packet.data(), static_cast<int>(packet.size()), &got, 5) != 0 || got == 0)
      break;
  }
}

bool UsbLink::emergency_write(const uint8_t* data, size_t size) noexcept {
  usbdevfs_bulktransfer bulk{};
  bulk.ep = out_ep_;
  bulk.len = static_cast<unsigned>(size);
  bulk.timeout = 200;
  bulk.data = const_cast<uint8_t*>(data);
  const int sent = ioctl(fd_, USBDEVFS_BULK, &bulk);
  if (sent > 0) ledger_.record(data, static_cast<size_t>(sent));
  return sent == static_cast<int>(size);
}

}  // namespace bodyscan::hw::usb
