// The stripe extraction (recon/scan) on what the simulated rig renders, against the
// simulator's ground truth: the surface seen at each sub-pixel sample lies on the
// laser's plane.
#include <gtest/gtest.h>

#include <cmath>

#include "hw/sim/sim_rig.hpp"
#include "recon/scan/stripe.hpp"

namespace bodyscan::hw::sim {
namespace {

TEST(StripeOnBody, SamplesLieOnTheLaserPlane) {
  auto desc = load_rig_description(*shipped_rig_path("thesis"));
  ASSERT_TRUE(desc.ok());
  desc->cameras.resize(1);  // front-left, full resolution
  auto made = SimulatedRig::create(*desc);
  ASSERT_TRUE(made.ok()) << made.status().message();
  SimulatedRig& rig = **made;
  Controller& c = rig.controller();
  LasersOff off(c);
  const LaserDescription& l = desc->lasers[0];
  ASSERT_TRUE(c.home(0).ok());
  auto base = rig.camera(0).grab();
  ASSERT_TRUE(base.ok());
  double ss = 0;
  size_t n = 0, on_body = 0;
  for (int step : {-100, -40, 20, 80}) {
    ASSERT_TRUE(c.move_to(0, step).ok());
    ASSERT_TRUE(c.set_laser(0, true).ok());
    auto frame = rig.camera(0).grab();
    ASSERT_TRUE(frame.ok());
    auto samples = extract_stripe({frame->pixels.data(), frame->width, frame->height},
                                  {base->pixels.data(), base->width, base->height}, {.threshold = 30, .radius = 4});
    ASSERT_TRUE(samples.ok());
    for (const StripeSample& s : *samples) {
      const Hit h = rig.renderer(0).surface_at(rig.scene(), Vec2d(s.column, s.row));
      if (h.surface == Surface::kNone) continue;
      const double d = l.plane_normal(step).dot(h.position) - l.plane_offset(step);
      if (std::abs(d) > 20) continue;  // the row's peak was elsewhere (floor glare)
      ss += d * d;
      ++n;
      on_body += h.surface == Surface::kSubject;
    }
  }
  ASSERT_GT(on_body, 300u);
  const double rms = std::sqrt(ss / n);
  // Speckle (contrast 0.25) and sensor noise on a ~1.4 mm pixel footprint.
  EXPECT_LT(rms, 0.5) << "mm";
  std::printf("[ stripe on body ] %zu samples (%zu on the body), plane distance RMS %.3f mm\n", n, on_body, rms);
}

}  // namespace
}  // namespace bodyscan::hw::sim
