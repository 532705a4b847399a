// `bodyscan devices`: the cameras and controller boards this machine can reach, with
// the ids a rig description uses for them (docs/hardware.md, "Bring-up").
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "core/command_line.hpp"
#include "hw/aravis/aravis_camera.hpp"
#include "hw/usb/usb_link.hpp"

namespace bodyscan::cli {

namespace {
constexpr const char* kUsage =
    "usage: bodyscan devices [--json] [--include-fake]\n"
    "\n"
    "Lists the GenICam cameras Aravis finds (GigE Vision on every network interface,\n"
    "USB3 Vision), the USB devices (naming the controller boards bodyscan drives) and\n"
    "the serial ports under /dev/serial/by-id. A rig description names a camera by the\n"
    "id shown here (or its IP address) and a board by its USB ids or serial port.\n"
    "\n"
    "  --json          one JSON document on stdout\n"
    "  --include-fake  also Aravis' in-process fake camera (Fake_1), to try the tools\n";
}  // namespace

int run_devices(int argc, char** argv) {
  bool json_out = false, fake = false;
  CommandLine cl("bodyscan devices", kUsage);
  cl.flag("--json", &json_out);
  cl.flag("--include-fake", &fake);
  if (const auto exit = cl.parse(argc, argv)) return *exit;
  const auto cameras = hw::aravis::list_cameras(fake);
  auto usb = hw::usb::list_usb_devices();
  std::vector<std::string> ports;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator("/dev/serial/by-id", ec)) ports.push_back(e.path().string());

  if (json_out) {
    nlohmann::json j;
    j["cameras"] = nlohmann::json::array();
    for (const auto& c : cameras)
      j["cameras"].push_back({{"id", c.id},
                              {"vendor", c.vendor},
                              {"model", c.model},
                              {"serial", c.serial},
                              {"protocol", c.protocol},
                              {"address", c.address}});
    j["usb"] = nlohmann::json::array();
    if (usb.ok()) {
      for (const auto& d : *usb) {
        char ids[16];
        std::snprintf(ids, sizeof ids, "%04x:%04x", d.vendor, d.product);
        j["usb"].push_back({{"ids", ids},
                            {"bus", d.bus},
                            {"address", d.address},
                            {"manufacturer", d.manufacturer},
                            {"product", d.product_name},
                            {"serial", d.serial},
                            {"bodyscan_board", d.known_as}});
      }
    } else {
      j["usb_error"] = usb.status().message();
    }
    j["serial_ports"] = ports;
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  std::printf("Cameras (Aravis):\n");
  if (cameras.empty()) std::printf("  none found (check the network link, its MTU, and that the camera is powered)\n");
  for (const auto& c : cameras)
    std::printf("  %-32s %s %s, serial %s, %s at %s\n", c.id.c_str(), c.vendor.c_str(), c.model.c_str(),
                c.serial.c_str(), c.protocol.c_str(), c.address.c_str());
  std::printf("USB devices:\n");
  if (!usb.ok())
    std::printf("  %s\n", usb.status().message().c_str());
  else if (usb->empty())
    std::printf("  none\n");
  else
    for (const auto& d : *usb)
      std::printf("  %04x:%04x bus %d device %d  %s %s%s%s%s\n", d.vendor, d.product, d.bus, d.address,
                  d.manufacturer.c_str(), d.product_name.c_str(),
                  d.serial.empty() ? "" : (", serial " + d.serial).c_str(), d.known_as.empty() ? "" : "  <- ",
                  d.known_as.c_str());
  std::printf("Serial ports:\n");
  if (ports.empty()) std::printf("  none under /dev/serial/by-id\n");
  for (const auto& p : ports) std::printf("  %s\n", p.c_str());
  return 0;
}

}  // namespace bodyscan::cli
