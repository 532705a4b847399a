// The Aravis camera without hardware, against Aravis' own simulators:
// - the in-process fake camera ("Fake_1"), whose image we draw (a fill pattern),
//   so every pixel is checked;
// - the GigE Vision simulator arv-fake-gv-camera-0.8 (Debian's aravis-tools),
//   a separate process on a loopback address: the real GVCP/GVSP protocol path,
//   including lost packets and the camera vanishing mid-stream.
#include "hw/aravis/aravis_camera.hpp"

#include <arv.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <thread>

namespace bodyscan::hw::aravis {
namespace {

using namespace std::chrono_literals;

CameraDescription fake_description(const std::string& id, int size = 512) {
  CameraDescription d;
  d.id = "front-left";
  d.width = size;
  d.height = size;
  d.device.backend = "aravis";
  d.device.id = id;
  d.exposure_us = 2000;
  d.device.timeout_ms = 2000;
  return d;
}

// Aravis' fake draws a diagonal ramp: a pixel depends on x + y (and the frame).
// Returns how many sampled pixels break that.
int off_diagonal(const Frame& f) {
  int wrong = 0;
  for (int y = 0; y + 1 < f.height; y += 7)
    for (int x = 0; x + 1 < f.width; x += 5) wrong += f.at(x + 1, y) != f.at(x, y + 1);
  return wrong;
}

TEST(AravisCamera, FakeCameraFramesArriveWhole) {
  auto cam = AravisCamera::open(fake_description("Fake_1"));
  ASSERT_TRUE(cam.ok()) << cam.status().message();
  EXPECT_EQ((*cam)->info().id, "front-left");
  EXPECT_EQ((*cam)->info().vendor, "Aravis");
  EXPECT_EQ((*cam)->info().width, 512);
  auto f = (*cam)->grab(2000ms);
  ASSERT_TRUE(f.ok()) << f.status().message();
  EXPECT_EQ(f->width, 512);
  EXPECT_EQ(f->pixels.size(), 512u * 512u);
  EXPECT_EQ(f->format, PixelFormat::kMono8);
  EXPECT_LE(off_diagonal(*f), 60);  // where the ramp wraps
  EXPECT_NE(f->at(0, 0), f->at(100, 0));
  auto g = (*cam)->grab(2000ms);
  ASSERT_TRUE(g.ok());
  EXPECT_EQ(g->frame_id, f->frame_id + 1);
  EXPECT_NE(g->pixels, f->pixels);  // the ramp moves from frame to frame

  // 16 bits: the frame size changes, the stream is rebuilt.
  ASSERT_TRUE((*cam)->set_pixel_format(PixelFormat::kMono16).ok());
  auto h = (*cam)->grab(2000ms);
  ASSERT_TRUE(h.ok()) << h.status().message();
  EXPECT_EQ(h->max_value(), 65535);
  EXPECT_LE(off_diagonal(*h), 60);
  int above_8_bits = 0;
  for (uint16_t p : h->pixels) above_8_bits += p > 255;
  EXPECT_GT(above_8_bits, 1000);
  EXPECT_FALSE((*cam)->set_pixel_format(PixelFormat::kMono12).ok());  // the fake has no Mono12

  ASSERT_TRUE((*cam)->set_exposure_us(5000).ok());
  EXPECT_NEAR((*cam)->exposure_us(), 5000, 1);
  EXPECT_EQ((*cam)->grab(2000ms)->exposure_us, (*cam)->exposure_us());
}

// A hardware trigger: the camera set to Line0 sends no frame of its own accord
// and no software trigger is sent; the fake camera pulses that line itself (a
// frame every ~20 ms here), so each grab gets the frame of the next pulse. A line
// the camera does not have is refused when opening, naming it.
TEST(AravisCamera, LineTriggerTakesFramesFromTheLine) {
  CameraDescription d = fake_description("Fake_1");
  d.device.trigger = "Line0";
  auto cam = AravisCamera::open(d);
  ASSERT_TRUE(cam.ok()) << cam.status().message();
  uint64_t last = 0;
  for (int i = 0; i < 5; ++i) {
    auto f = (*cam)->grab(2000ms);
    ASSERT_TRUE(f.ok()) << f.status().message();
    EXPECT_EQ(f->pixels.size(), 512u * 512u);
    EXPECT_LE(off_diagonal(*f), 60);
    if (i > 0) {
      EXPECT_GT(f->frame_id, last);
    }
    last = f->frame_id;
  }
  d.device.trigger = "Line7";
  auto wrong = AravisCamera::open(d);
  ASSERT_FALSE(wrong.ok());
  EXPECT_EQ(wrong.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(wrong.status().message().find("'Line7'"), std::string::npos) << wrong.status().message();
}

TEST(AravisCamera, DescriptionThatDoesNotMatchTheCameraIsRefused) {
  auto cam = AravisCamera::open(fake_description("Fake_1", 4096));
  ASSERT_FALSE(cam.ok());
  EXPECT_NE(cam.status().message().find("2048 x 2048 pixel sensor"), std::string::npos) << cam.status().message();
  auto none = AravisCamera::open(fake_description("NoSuchVendor-NoModel-0000"));
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.status().code(), StatusCode::kUnavailable);
  EXPECT_NE(none.status().message().find("bodyscan devices"), std::string::npos);
}

// arv-fake-gv-camera-0.8 on its own loopback address (tests run in parallel).
class GvSimulator {
 public:
  GvSimulator(const std::string& address, int lost_per_thousand) : address_(address) {
    pid_ = fork();
    if (pid_ == 0) {
      const std::string lost = std::to_string(lost_per_thousand);
      execlp("arv-fake-gv-camera-0.8", "arv-fake-gv-camera-0.8", "-i", address.c_str(), "-s", "GVTEST", "-r",
             lost.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    std::this_thread::sleep_for(300ms);  // until it listens
  }
  ~GvSimulator() { stop(); }
  void stop() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
  }
  bool running() { return pid_ > 0 && waitpid(pid_, nullptr, WNOHANG) == 0; }

 private:
  std::string address_;
  pid_t pid_ = -1;
};

// One test for the simulator: it only listens on an address an interface has
// (127.0.0.1), and the discovery port is fixed, so two would collide in parallel.
TEST(AravisCamera, GigEVisionSimulatorOverLoopback) {
  {
    // 0.2 % of stream packets lost: packet resend recovers most frames; any frame it
    // cannot complete is an error that says what to check, never a torn image.
    GvSimulator lossy("127.0.0.1", 2);
    ASSERT_TRUE(lossy.running()) << "arv-fake-gv-camera-0.8 (aravis-tools) did not start";
    auto cam = AravisCamera::open(fake_description("127.0.0.1"));
    ASSERT_TRUE(cam.ok()) << cam.status().message();
    int good = 0, reported = 0;
    for (int i = 0; i < 20; ++i) {
      auto f = (*cam)->grab(2000ms);
      if (f.ok()) {
        ++good;
        EXPECT_EQ(f->pixels.size(), 512u * 512u);
      } else {
        ++reported;
        EXPECT_NE(f.status().message().find("front-left"), std::string::npos);
        EXPECT_NE(f.status().message().find("incomplete frame"), std::string::npos) << f.status().message();
      }
    }
    EXPECT_GT(good, 10) << reported << " frames failed";
    std::printf("lost packets 0.2 %%: %d of 20 frames complete, %d reported\n", good, reported);
  }
  GvSimulator sim("127.0.0.1", 0);
  ASSERT_TRUE(sim.running());
  auto cam = AravisCamera::open(fake_description("127.0.0.1"));
  ASSERT_TRUE(cam.ok()) << cam.status().message();
  EXPECT_EQ((*cam)->info().serial, "GVTEST");
  for (int i = 0; i < 5; ++i) {
    auto f = (*cam)->grab(2000ms);
    ASSERT_TRUE(f.ok()) << f.status().message();
    EXPECT_EQ(f->width, 512);
    // The simulator's own pattern is not flat.
    EXPECT_NE(f->at(10, 10), f->at(300, 400));
  }
  EXPECT_GE((*cam)->statistics().completed, 5u);

  // The camera vanishes mid-scan: every grab fails with its name, and soon as gone.
  sim.stop();
  Status last;
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < 20s) {
    auto f = (*cam)->grab(500ms);
    ASSERT_FALSE(f.ok());
    last = f.status();
    EXPECT_NE(last.message().find("front-left"), std::string::npos) << last.message();
    if (last.code() == StatusCode::kUnavailable) break;
  }
  EXPECT_EQ(last.code(), StatusCode::kUnavailable) << last.message();
  std::printf("after the simulator died: %s (%.1f s)\n", last.message().c_str(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

}  // namespace
}  // namespace bodyscan::hw::aravis
