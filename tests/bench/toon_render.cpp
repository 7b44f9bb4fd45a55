// The toon head per kiosk frame: renderToonBgra at 480 px (and 320, 720) on a real FRMDB pair's model, plus the
// one-off costs (the model from the photos, the radius). 30 fps needs under 33 ms a frame. Prints figures; never
// fails on speed. Needs ../shared/data (or $AVATARBOOTH_SHARED_DATA).
#include "common/image_io.h"
#include "test_paths.h"
#include "reveal/toon/toon_billboard.h"

#include <benchmark/benchmark.h>

#include <cstdio>

using namespace avatarbooth;

namespace {

const cv::Mat& frontPhoto() {
    static const cv::Mat m = readPhoto(test::sharedData() / "frmdb" / "001" / "Img_33.jpg");
    return m;
}
const cv::Mat& sidePhoto() {
    static const cv::Mat m = readPhoto(test::sharedData() / "frmdb" / "001" / "Img_13.jpg");
    return m;
}
const toon::ToonModel& model() {
    static const toon::ToonModel m = toon::toonFromPhotoPair(frontPhoto(), sidePhoto());
    return m;
}

void BM_ToonModelFromPhotos(benchmark::State& state) {
    for (auto _ : state) benchmark::DoNotOptimize(toon::toonFromPhotoPair(frontPhoto(), sidePhoto()));
}
BENCHMARK(BM_ToonModelFromPhotos)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_ToonRadius(benchmark::State& state) {
    for (auto _ : state) benchmark::DoNotOptimize(toon::toonRadius(model()));
}
BENCHMARK(BM_ToonRadius)->Unit(benchmark::kMicrosecond);

// One frame: yaw stepping through the whole turn as the kiosk animates it; the radius computed once (as the kiosk
// would) or per frame (radius 0).
void BM_ToonFrameBgra(benchmark::State& state) {
    const int side = static_cast<int>(state.range(0));
    const bool radiusOnce = state.range(1) != 0;
    const double radius = radiusOnce ? toon::toonRadius(model()) : 0.0;
    double yaw = -90.0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(toon::renderToonBgra(model(), yaw, {side, side}, radius));
        yaw = yaw >= 90.0 ? -90.0 : yaw + 3.0;
    }
    state.counters["pairs"] = static_cast<double>(model().pairs.size());
    state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ToonFrameBgra)->ArgsProduct({{320, 480, 720}, {1}})->Args({480, 0})->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
    if (!test::haveSharedData()) {
        std::printf("bench_toon_render: sample data not found at %s (set AVATARBOOTH_SHARED_DATA); nothing to measure\n",
                    test::sharedData().c_str());
        return 0;
    }
    model();  // built once before timing (BM_ToonModelFromPhotos measures that)
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
