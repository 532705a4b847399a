// Lens correction (thesis §3.1.1) on the simulated thesis rig's "back" camera
// (1280 x 1024, the strongest distortion): the dot-grid image it takes of the board
// 800 mm away, then each step of the calibration, and the per-scan costs -
// correct() on stripe samples (about 5 million a scan) and the display remap.
//
//   lens_benchmark [--benchmark_filter=...]   (Google Benchmark options)
#include <benchmark/benchmark.h>

#include <random>

#include "hw/sim/dot_grid.hpp"
#include "recon/calib/lens_correction.hpp"

using namespace bodyscan;

namespace {

struct Board {
  hw::Frame frame;
  ImageView view() const { return {frame.pixels.data(), frame.width, frame.height}; }
  Board() {
    const hw::RigDescription desc = *hw::load_rig_description(*hw::shipped_rig_path("thesis"));
    const hw::CameraDescription& cam = desc.cameras.back();
    frame = hw::sim::render_dot_grid(cam, desc.simulation, hw::sim::dot_grid_for(cam.model()), 1);
  }
};
const Board& board() {
  static const Board b;
  return b;
}
const LensCorrection& lens() {
  static const LensCorrection l = *calibrate_lens(board().view());
  return l;
}

void BM_FindDots(benchmark::State& state) {
  const ImageView image = board().view();
  size_t dots = 0;
  for (auto _ : state) {
    auto d = find_dots(image);
    dots = d->size();
    benchmark::DoNotOptimize(d);
  }
  state.counters["dots"] = static_cast<double>(dots);
}
BENCHMARK(BM_FindDots)->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_IndexGrid(benchmark::State& state) {
  const std::vector<Dot> dots = *find_dots(board().view());
  for (auto _ : state) benchmark::DoNotOptimize(index_grid(dots));
}
BENCHMARK(BM_IndexGrid)->Unit(benchmark::kMillisecond);

void BM_CalibrateLens(benchmark::State& state) {
  const ImageView image = board().view();
  for (auto _ : state) benchmark::DoNotOptimize(calibrate_lens(image));
}
BENCHMARK(BM_CalibrateLens)->UseRealTime()->Unit(benchmark::kMillisecond);

// Stripe samples come a row at a time: a slanted line of points per frame.
std::vector<Eigen::Vector2d> stripe_samples(int n) {
  std::vector<Eigen::Vector2d> p;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> column(0, 1279), slope(-0.3, 0.3);
  while (static_cast<int>(p.size()) < n) {
    const double x0 = column(rng), s = slope(rng);
    for (int row = 0; row < 1024 && static_cast<int>(p.size()) < n; ++row)
      p.emplace_back(std::clamp(x0 + s * row, 0.0, 1279.0), row);
  }
  return p;
}

void BM_Correct(benchmark::State& state) {
  const LensCorrection& l = lens();
  const std::vector<Eigen::Vector2d> p = stripe_samples(1 << 20);
  for (auto _ : state) {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& q : p) sum += l.correct(q);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(p.size()));
}
BENCHMARK(BM_Correct)->Unit(benchmark::kMillisecond);

void BM_Distort(benchmark::State& state) {
  const LensCorrection& l = lens();
  const std::vector<Eigen::Vector2d> p = stripe_samples(1 << 16);
  for (auto _ : state) {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& q : p) sum += l.distort(q);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(p.size()));
}
BENCHMARK(BM_Distort)->Unit(benchmark::kMillisecond);

void BM_Remap(benchmark::State& state) {
  const LensCorrection& l = lens();
  const ImageView image = board().view();
  for (auto _ : state) benchmark::DoNotOptimize(l.remap(image));
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * image.width * image.height);
}
BENCHMARK(BM_Remap)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
