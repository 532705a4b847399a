#include "hw/aravis/aravis_camera.hpp"

#include <arv.h>

#include <atomic>
#include <cmath>

#include "hw/aravis/pixel_unpack.hpp"

namespace bodyscan::hw::aravis {

namespace {

constexpr int kBuffers = 6;

// Owns a GError and turns it into a message.
struct Err {
  GError* e = nullptr;
  ~Err() {
    if (e) g_error_free(e);
  }
  GError** out() {
    if (e) g_clear_error(&e);
    return &e;
  }
  explicit operator bool() const { return e != nullptr; }
  std::string text() const { return e ? e->message : "unknown error"; }
};

template <typename T>
struct GObj {
  T* p = nullptr;
  ~GObj() {
    if (p) g_object_unref(p);
  }
};

std::mutex g_arv_mutex;  // Aravis' device list is global

}  // namespace

std::vector<AravisDeviceInfo> list_cameras(bool include_fake) {
  std::lock_guard lock(g_arv_mutex);
  if (include_fake) arv_enable_interface("Fake");
  arv_update_device_list();
  std::vector<AravisDeviceInfo> out;
  const unsigned n = arv_get_n_devices();
  auto s = [](const char* c) { return std::string(c ? c : ""); };
  for (unsigned i = 0; i < n; ++i) {
    out.push_back({s(arv_get_device_id(i)), s(arv_get_device_vendor(i)), s(arv_get_device_model(i)),
                   s(arv_get_device_serial_nbr(i)), s(arv_get_device_protocol(i)), s(arv_get_device_address(i))});
  }
  return out;
}

struct AravisCamera::Impl {
  std::string name;  // for messages: "camera 'front-left' (Basler-123)"
  ArvCamera* camera = nullptr;
  ArvStream* stream = nullptr;
  bool software_trigger = true;
  std::chrono::milliseconds frame_timeout{2000};
  std::atomic<bool> lost{false};
  gulong lost_handler = 0;
  uint64_t frames = 0;
  std::vector<uint32_t> formats;  // PFNC codes the camera offers
  uint32_t pfnc = kPfncMono8;

  ~Impl() {
    if (camera) {
      GError* e = nullptr;
      arv_camera_stop_acquisition(camera, &e);
      if (e) g_error_free(e);
    }
    if (stream) g_object_unref(stream);
    if (camera) {
      if (lost_handler) g_signal_handler_disconnect(arv_camera_get_device(camera), lost_handler);
      g_object_unref(camera);
    }
  }

  static void on_control_lost(ArvDevice*, gpointer self) { static_cast<Impl*>(self)->lost = true; }

  Status unplugged() const {
    return unavailable(name +
                       " is gone: it stopped answering its control channel (unplugged, powered off, or the network "
                       "link is down)");
  }
};

AravisCamera::AravisCamera(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

AravisCamera::~AravisCamera() = default;

void* AravisCamera::device() const { return arv_camera_get_device(impl_->camera); }

StatusOr<std::unique_ptr<AravisCamera>> AravisCamera::open(const CameraDescription& desc) {
  auto impl = std::make_unique<Impl>();
  impl->name = "camera '" + desc.id + "' (" + desc.device.id + ")";
  impl->frame_timeout = std::chrono::milliseconds(desc.device.timeout_ms);
  impl->software_trigger = desc.device.trigger == "software";
  Err err;
  {
    std::lock_guard lock(g_arv_mutex);
    if (desc.device.id.rfind("Fake", 0) == 0) arv_enable_interface("Fake");
    impl->camera = arv_camera_new(desc.device.id.c_str(), err.out());
  }
  if (!impl->camera) {
    return unavailable("cannot open " + impl->name + ": " + err.text() +
                       " (is it connected and powered? `bodyscan devices` lists the cameras found)");
  }
  impl->lost_handler = g_signal_connect(arv_camera_get_device(impl->camera), "control-lost",
                                        G_CALLBACK(&Impl::on_control_lost), impl.get());

  CameraInfo info;
  info.id = desc.id;
  auto text = [&](const char* s) { return std::string(s ? s : ""); };
  info.vendor = text(arv_camera_get_vendor_name(impl->camera, err.out()));
  info.model = text(arv_camera_get_model_name(impl->camera, err.out()));
  info.serial = text(arv_camera_get_device_serial_number(impl->camera, err.out()));

  guint n = 0;
  gint64* formats = arv_camera_dup_available_pixel_formats(impl->camera, &n, err.out());
  for (guint i = 0; i < n; ++i) {
    const auto code = static_cast<uint32_t>(formats[i]);
    impl->formats.push_back(code);
    const int bits = pfnc_bits(code);
    auto add = [&](PixelFormat f) {
      for (PixelFormat g : info.formats)
        if (g == f) return;
      info.formats.push_back(f);
    };
    if (bits == 8) add(PixelFormat::kMono8);
    if (bits == 12) add(PixelFormat::kMono12);
    if (bits == 16) add(PixelFormat::kMono16);
  }
  g_free(formats);
  if (info.formats.empty()) {
    return failed_precondition(impl->name +
                               " offers no monochrome pixel format (Mono8, Mono12 or Mono16): bodyscan "
                               "needs a monochrome camera");
  }

  // The description's image size, from the sensor's top-left corner.
  gint sx = 0, sy = 0;
  arv_camera_get_sensor_size(impl->camera, &sx, &sy, err.out());
  if (err) return io_error("cannot read the sensor size of " + impl->name + ": " + err.text());
  if (desc.width > sx || desc.height > sy) {
    return failed_precondition(impl->name + " has a " + std::to_string(sx) + " x " + std::to_string(sy) +
                               " pixel sensor, smaller than the rig description's " + std::to_string(desc.width) +
                               " x " + std::to_string(desc.height) + ": correct the description");
  }
  arv_camera_set_region(impl->camera, 0, 0, desc.width, desc.height, err.out());
  gint x = 0, y = 0, w = 0, h = 0;
  arv_camera_get_region(impl->camera, &x, &y, &w, &h, err.out());
  if (err) return io_error("cannot set the image size of " + impl->name + ": " + err.text());
  info.width = w;
  info.height = h;
  if (w != desc.width || h != desc.height) {
    return failed_precondition(impl->name + " delivers " + std::to_string(w) + " x " + std::to_string(h) +
                               " pixels, not the rig description's " + std::to_string(desc.width) + " x " +
                               std::to_string(desc.height) + ": correct the description");
  }

  // Manual exposure and gain: the laser's stripe must not be "corrected" away.
  if (arv_camera_is_exposure_auto_available(impl->camera, err.out()))
    arv_camera_set_exposure_time_auto(impl->camera, ARV_AUTO_OFF, err.out());
  if (arv_camera_is_gain_auto_available(impl->camera, err.out()))
    arv_camera_set_gain_auto(impl->camera, ARV_AUTO_OFF, err.out());
  arv_camera_set_acquisition_mode(impl->camera, ARV_ACQUISITION_MODE_CONTINUOUS, err.out());
  if (err) return io_error("cannot set up " + impl->name + ": " + err.text());
  arv_camera_set_trigger(impl->camera, impl->software_trigger ? "Software" : desc.device.trigger.c_str(), err.out());
  if (err) {
    return failed_precondition(impl->name + " cannot be triggered by '" + desc.device.trigger + "': " + err.text());
  }
  if (arv_camera_is_gv_device(impl->camera)) {
    if (desc.device.packet_size > 0)
      arv_camera_gv_set_packet_size(impl->camera, desc.device.packet_size, err.out());
    else
      arv_camera_gv_auto_packet_size(impl->camera, err.out());
    if (err) return io_error("cannot set the packet size of " + impl->name + ": " + err.text());
  }

  std::unique_ptr<AravisCamera> cam(new AravisCamera(std::move(impl)));
  cam->info_ = std::move(info);
  RETURN_IF_ERROR(cam->set_pixel_format(desc.pixel_format));
  RETURN_IF_ERROR(cam->set_exposure_us(desc.exposure_us));
  RETURN_IF_ERROR(cam->set_gain_db(desc.gain_db));
  RETURN_IF_ERROR(cam->restart_stream());
  return cam;
}

Status AravisCamera::restart_stream() {
  Impl& m = *impl_;
  Err err;
  if (m.stream) {
    arv_camera_stop_acquisition(m.camera, err.out());
    g_object_unref(m.stream);
    m.stream = nullptr;
  }
  m.stream = arv_camera_create_stream(m.camera, nullptr, nullptr, err.out());
  if (!m.stream) return io_error("cannot open the image stream of " + m.name + ": " + err.text());
  if (ARV_IS_GV_STREAM(m.stream)) {
    // Lost packets are asked for again before a frame is given up.
    g_object_set(m.stream, "packet-resend", ARV_GV_STREAM_PACKET_RESEND_ALWAYS, nullptr);
  }
  const guint payload = arv_camera_get_payload(m.camera, err.out());
  if (err || payload == 0) return io_error("cannot read the frame size of " + m.name + ": " + err.text());
  for (int i = 0; i < kBuffers; ++i) arv_stream_push_buffer(m.stream, arv_buffer_new(payload, nullptr));
  arv_camera_start_acquisition(m.camera, err.out());
  if (err) return io_error("cannot start " + m.name + ": " + err.text());
  return Status::Ok();
}

Status AravisCamera::set_pixel_format(PixelFormat format) {
  std::lock_guard lock(mutex_);
  Impl& m = *impl_;
  const int bits = bits_per_pixel(format);
  // Unpacked first (least work), then the packed layouts.
  uint32_t chosen = 0;
  for (uint32_t want : {kPfncMono8, kPfncMono12, kPfncMono16, kPfncMono12Packed, kPfncMono12p}) {
    if (pfnc_bits(want) != bits) continue;
    for (uint32_t have : m.formats)
      if (have == want && !chosen) chosen = want;
  }
  if (!chosen) {
    return invalid_argument(m.name + " has no " + to_string(format) + " pixel format");
  }
  Err err;
  const bool streaming = m.stream != nullptr;
  if (streaming) arv_camera_stop_acquisition(m.camera, err.out());
  arv_camera_set_pixel_format(m.camera, static_cast<ArvPixelFormat>(chosen), err.out());
  if (err) return io_error("cannot set " + m.name + " to " + pfnc_name(chosen) + ": " + err.text());
  m.pfnc = chosen;
  format_ = format;
  if (streaming) return restart_stream();  // the frame size may have changed
  return Status::Ok();
}

Status AravisCamera::set_exposure_us(double exposure) {
  std::lock_guard lock(mutex_);
  Err err;
  arv_camera_set_exposure_time(impl_->camera, exposure, err.out());
  if (err)
    return invalid_argument("cannot set the exposure of " + impl_->name + " to " + std::to_string(exposure) +
                            " us: " + err.text());
  exposure_us_ = arv_camera_get_exposure_time(impl_->camera, err.out());
  return Status::Ok();
}

Status AravisCamera::set_gain_db(double gain) {
  std::lock_guard lock(mutex_);
  Err err;
  if (!arv_camera_is_gain_available(impl_->camera, err.out())) {
    if (std::abs(gain) > 1e-9) return invalid_argument(impl_->name + " has no gain control");
    gain_db_ = 0;
    return Status::Ok();
  }
  arv_camera_set_gain(impl_->camera, gain, err.out());
  if (err)
    return invalid_argument("cannot set the gain of " + impl_->name + " to " + std::to_string(gain) +
                            " dB: " + err.text());
  gain_db_ = arv_camera_get_gain(impl_->camera, err.out());
  return Status::Ok();
}

AravisCamera::Statistics AravisCamera::statistics() const {
  std::lock_guard lock(mutex_);
  Statistics s;
  if (impl_->stream) {
    guint64 c = 0, f = 0, u = 0;
    arv_stream_get_statistics(impl_->stream, &c, &f, &u);
    s = {c, f, u};
  }
  return s;
}

StatusOr<Frame> AravisCamera::grab(std::chrono::milliseconds timeout) {
  std::lock_guard lock(mutex_);
  Impl& m = *impl_;
  if (m.lost) return m.unplugged();
  const auto wait = std::max(timeout, std::chrono::milliseconds(1));
  Status last;
  for (int attempt = 0; attempt < 2; ++attempt) {
    // Frames that arrived before this request (a hardware trigger's earlier pulse,
    // a late frame) are not this one.
    while (ArvBuffer* old = arv_stream_try_pop_buffer(m.stream)) arv_stream_push_buffer(m.stream, old);
    Err err;
    if (m.software_trigger) {
      arv_camera_software_trigger(m.camera, err.out());
      if (err) {
        if (m.lost) return m.unplugged();
        return unavailable(m.name + " does not answer its trigger (" + err.text() +
                           "): is it unplugged, powered off, or its network link down?");
      }
    }
    ArvBuffer* buf = arv_stream_timeout_pop_buffer(m.stream, static_cast<guint64>(wait.count()) * 1000u);
    if (m.lost) {
      if (buf) arv_stream_push_buffer(m.stream, buf);
      return m.unplugged();
    }
    if (!buf) {
      return deadline_exceeded(m.name + " sent no frame within " + std::to_string(wait.count()) + " ms" +
                               (m.software_trigger ? "" : " (is the trigger line wired and pulsing?)"));
    }
    const ArvBufferStatus status = arv_buffer_get_status(buf);
    if (status != ARV_BUFFER_STATUS_SUCCESS) {
      arv_stream_push_buffer(m.stream, buf);
      if (status == ARV_BUFFER_STATUS_MISSING_PACKETS || status == ARV_BUFFER_STATUS_WRONG_PACKET_ID ||
          status == ARV_BUFFER_STATUS_TIMEOUT || status == ARV_BUFFER_STATUS_SIZE_MISMATCH) {
        last = io_error(m.name + " delivered an incomplete frame (" +
                        (status == ARV_BUFFER_STATUS_MISSING_PACKETS ? std::string("packets lost")
                         : status == ARV_BUFFER_STATUS_TIMEOUT       ? std::string("packets late")
                         : status == ARV_BUFFER_STATUS_SIZE_MISMATCH ? std::string("wrong size")
                                                                     : std::string("packets out of order")) +
                        ", twice in a row): check the cable, the network card's MTU and jumbo frames, and the "
                        "camera's packet size and bandwidth");
        continue;  // one more try
      }
      last = io_error(m.name + " delivered a frame with status " + std::to_string(static_cast<int>(status)));
      continue;
    }
    Frame f;
    f.width = arv_buffer_get_image_width(buf);
    f.height = arv_buffer_get_image_height(buf);
    f.format = format_;
    f.frame_id = ++m.frames;
    f.timestamp_ns = static_cast<int64_t>(arv_buffer_get_timestamp(buf));
    f.exposure_us = exposure_us_;
    f.gain_db = gain_db_;
    size_t size = 0;
    const auto* data = static_cast<const uint8_t*>(arv_buffer_get_image_data(buf, &size));
    Status st = unpack_mono(static_cast<uint32_t>(arv_buffer_get_image_pixel_format(buf)), data, size, f.width,
                            f.height, f.pixels);
    arv_stream_push_buffer(m.stream, buf);
    if (!st.ok()) return Status(st.code(), m.name + ": " + st.message());
    return f;
  }
  return last;
}

}  // namespace bodyscan::hw::aravis
