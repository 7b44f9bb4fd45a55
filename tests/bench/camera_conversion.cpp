// Camera frame costs at 1280x720: YUYV and MJPEG to BGR (the V4L2 backend's per-frame work), the sim camera's
// noise, and one whole sim preview frame. Prints figures; never fails on speed.
#include "drivers/camera/frame_conversion.h"
#include "drivers/camera/sim_camera.h"

#include <benchmark/benchmark.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <thread>

using namespace avatarbooth;

namespace {

constexpr int kWidth = 1280, kHeight = 720;

// A frame with smooth content and detail (what a camera sees), as BGR.
cv::Mat sceneLike() {
    cv::Mat image(kHeight, kWidth, CV_8UC3);
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x)
            image.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<std::uint8_t>(x * 255 / kWidth), static_cast<std::uint8_t>(y * 255 / kHeight),
                                                  static_cast<std::uint8_t>(((x / 40 + y / 40) % 2) * 120 + 60));
    cv::circle(image, {640, 360}, 200, cv::Scalar(180, 160, 140), -1, cv::LINE_AA);
    return image;
}

std::vector<std::uint8_t> yuyvFrame() {
    // YUYV from BGR: OpenCV has no direct BGR->YUYV, so build it from limited-range YUV per pixel pair.
    const cv::Mat bgr = sceneLike();
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(kWidth) * kHeight * 2);
    auto* out = bytes.data();
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; x += 2) {
            const auto a = bgr.at<cv::Vec3b>(y, x), b = bgr.at<cv::Vec3b>(y, x + 1);
            auto p2 = [](int u, int v) { return (u + v) / 2; };
            auto luma = [](cv::Vec3b p) { return static_cast<std::uint8_t>(16 + (66 * p[2] + 129 * p[1] + 25 * p[0]) / 256); };
            const int r = p2(a[2], b[2]), g = p2(a[1], b[1]), bl = p2(a[0], b[0]);
            *out++ = luma(a);
            *out++ = static_cast<std::uint8_t>(128 + (-38 * r - 74 * g + 112 * bl) / 256);
            *out++ = luma(b);
            *out++ = static_cast<std::uint8_t>(128 + (112 * r - 94 * g - 18 * bl) / 256);
        }
    return bytes;
}

void yuyvToBgr720p(benchmark::State& state) {
    const auto frame = yuyvFrame();
    for (auto _ : state) benchmark::DoNotOptimize(yuyvToBgr(frame, kWidth, kHeight));
    state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void mjpegToBgr720p(benchmark::State& state) {
    std::vector<std::uint8_t> jpeg;
    cv::imencode(".jpg", sceneLike(), jpeg, {cv::IMWRITE_JPEG_QUALITY, 85});
    for (auto _ : state) benchmark::DoNotOptimize(mjpegToBgr(jpeg, kWidth, kHeight));
    state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["jpeg_kB"] = static_cast<double>(jpeg.size()) / 1024.0;
}

void simNoise720p(benchmark::State& state) {
    const cv::Mat clean = sceneLike();
    cv::Mat frame;
    const SensorNoise noise(clean.total() * clean.elemSize(), 1, 2);
    std::uint64_t seed = 0;
    for (auto _ : state) {
        clean.copyTo(frame);
        noise.apply(frame, ++seed);
        benchmark::DoNotOptimize(frame.data);
    }
}

void simPreviewFrame720p(benchmark::State& state) {
    const auto dir = std::filesystem::temp_directory_path() / "bench_camera_conversion";
    std::filesystem::create_directories(dir);
    const cv::Mat image = sceneLike();
    cv::imwrite((dir / "front.png").string(), image);
    cv::imwrite((dir / "side.png").string(), image);
    SimCameraOptions options;
    options.folder = dir;
    options.fps = 1e6;  // never waits: measures the frame's own cost
    SimCamera camera(options, nullptr, std::make_shared<ManualClock>(SteadyTime{}));
    for (auto _ : state) benchmark::DoNotOptimize(camera.nextFrame(std::chrono::milliseconds(100)));
    state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
    std::filesystem::remove_all(dir);
}

}  // namespace

BENCHMARK(yuyvToBgr720p)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(mjpegToBgr720p)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(simNoise720p)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(simPreviewFrame720p)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);

BENCHMARK_MAIN();
