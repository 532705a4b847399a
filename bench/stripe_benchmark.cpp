// Stripe extraction throughput (thesis §3.1.4), megapixels per second of camera
// frames on all cores: 1280x1024 frames (the thesis cameras) with sensor noise and a
// slanted stripe, each against its base frame.
//
//   stripe_benchmark [--benchmark_filter=...]   (Google Benchmark options)
//
// The floor is 250 MPix/s (three 1.3 MPix cameras at 60 fps); the figure is
// "items_per_second" (pixels).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "recon/scan/stripe.hpp"

using namespace bodyscan;

namespace {

struct Frames {
  int w = 1280, h = 1024;
  std::vector<uint16_t> frame, base;
  Frames() {
    std::mt19937 rng(4);
    std::normal_distribution<double> noise(0, 1.5);
    frame.resize(static_cast<size_t>(w) * h);
    base.resize(frame.size());
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double ambient = 6 + 4 * std::sin(0.01 * x) * std::cos(0.013 * y);
        const double d = x - (400 + 0.3 * y);
        const double laser = 200 * std::exp(-0.5 * d * d / 1.44);
        const size_t i = static_cast<size_t>(y) * w + x;
        base[i] = static_cast<uint16_t>(std::clamp(std::round(ambient + noise(rng)), 0.0, 255.0));
        frame[i] = static_cast<uint16_t>(std::clamp(std::round(ambient + laser + noise(rng)), 0.0, 255.0));
      }
  }
};

void BM_ExtractStripe(benchmark::State& state) {
  static const Frames f;
  const ImageView frame{f.frame.data(), f.w, f.h}, base{f.base.data(), f.w, f.h};
  size_t samples = 0;
  for (auto _ : state) {
    auto s = extract_stripe(frame, base);
    samples += s->size();
    benchmark::DoNotOptimize(s);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * f.w * f.h);
  state.counters["rows_found"] = static_cast<double>(samples) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_ExtractStripe)->UseRealTime()->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
