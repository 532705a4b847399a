// What a camera of the simulated rig sees: the scene under room and frame lights,
// laser stripes where the laser reaches a surface the camera sees, lens distortion
// (rays are cast through the distorted pixels), speckle, shot and read noise,
// saturation. Deterministic for a seed and frame number.
#pragma once

#include <cstdint>
#include <mutex>
#include <utility>
#include <vector>

#include "hw/camera.hpp"
#include "hw/camera_model.hpp"
#include "hw/sim/scene.hpp"

namespace bodyscan::hw::sim {

struct ActiveLaser {
  const LaserDescription* laser = nullptr;
  int step = 0;
};

struct Lighting {
  bool room_lights = false;
  bool front_frame_lights = false;  // the front poles' lights (Z > 0)
  bool back_frame_lights = false;
  std::vector<Vec3d> dead_lights;   // frame lights (centres) that stay dark when switched on
  std::vector<ActiveLaser> lasers;  // the lasers that are on, at their steps
};

struct Exposure {
  PixelFormat format = PixelFormat::kMono8;
  double exposure_us = 10000;
  double gain_db = 0;
};

// The lens's point spread: a separable Gaussian of `sigma` pixels over the
// irradiance (nothing when sigma is 0).
void blur(std::vector<float>& irradiance, int width, int height, double sigma);

// Turns irradiance (fraction of full scale at the reference exposure of 10 ms, 0 dB)
// into a frame: shot and read noise, gain, quantisation, saturation. Deterministic
// for a seed.
Frame expose(const std::vector<float>& irradiance, const CameraDescription& camera, const Exposure& exposure,
             uint64_t seed);

// One camera's renderer: keeps the camera's pixel rays (distortion inverted once).
class Renderer {
 public:
  Renderer(const CameraDescription& camera, const SimulationDescription& sim);
  const CameraModel& model() const { return model_; }

  // Renders one frame of the scene as it is now. `frame_number` seeds the noise.
  Frame render(const Scene& scene, const Lighting& lighting, const Exposure& exposure, uint64_t frame_number) const;

  // The noise-free irradiance image, fraction of full scale at the reference
  // exposure (10 ms, 0 dB): what render() starts from. For tests.
  std::vector<float> irradiance(const Scene& scene, const Lighting& lighting) const;

  // Ground truth: the surface point seen through a (sub-)pixel, if any.
  Hit surface_at(const Scene& scene, const Vec2d& pixel) const;
  // Drops the cached lights-only images (the lights themselves changed).
  void forget_lights();

 private:
  // What each pixel's ray hits, cast once per scene version: a still scene is cast
  // once for all its frames, and each frame only adds shadow rays near the stripes.
  struct CachedHit {
    Vec3f position = Vec3f::Zero();
    Vec3f normal = Vec3f::Zero();
    Surface surface = Surface::kNone;
  };
  const std::vector<CachedHit>& hits(const Scene& scene) const;
  // Adds the lasers' stripes to `irradiance`: each pixel that can hold laser light
  // is integrated over its area with kLaserSubpixels^2 rays (each with its own hit,
  // distance from the plane and shadow), and that light is spread over the pixels
  // within the lens's point spread, as optics spread it before the sensor samples
  // it. Speckle (std/mean `speckle_contrast`, keyed by `speckle_seed`) multiplies
  // each pixel's laser light.
  //
  // A profile evaluated at the pixel's centre ray alone, widened by the footprint
  // on the tangent plane, put grazing views' points up to 1.6 mm inside the body
  // (bench/stripe_fidelity): near a silhouette the surface is not its tangent
  // plane over a pixel, and a spread folded into the profile cannot spill past it.
  void add_laser_light(const Scene& scene, const Lighting& lighting, std::vector<float>& irradiance,
                       uint64_t speckle_seed, double speckle_contrast) const;
  static constexpr int kLaserSubpixels = 4;
  // The irradiance without lasers, per room/frame light state, per scene version.
  const std::vector<float>& base_irradiance(const Scene& scene, const Lighting& lighting) const;
  // A moving scene's cache also keeps the image before the blur and after its first
  // (across) pass, so a new pose redraws only the part of the image it can change.
  struct BaseCache {
    uint64_t version = 0;
    std::vector<float> irradiance, unblurred, across;
  };

  CameraDescription camera_;
  SimulationDescription sim_;
  CameraModel model_;
  // Per pixel, unit, world (zero where the lens model fails), worked out on the first
  // frame: a rig that is opened and never rendered (a server that only serves its
  // archive) does not pay a lens inversion per pixel.
  const std::vector<Vec3f>& rays() const;
  mutable std::once_flag rays_once_;
  mutable std::vector<Vec3f> rays_;
  mutable std::mutex cache_mutex_;
  mutable std::vector<CachedHit> hits_;
  mutable uint64_t hits_version_ = 0;
  // Per image row, the spans of columns (first, last) a moving subject can change
  // in the scene range moving_range_ (no rows: not known, the whole image is redrawn).
  mutable std::vector<std::vector<std::pair<int, int>>> moving_;
  mutable uint64_t moving_range_ = 0;
  mutable BaseCache base_[8];  // by room, front and back frame lights
};

}  // namespace bodyscan::hw::sim
