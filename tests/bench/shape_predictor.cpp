// The 68-point landmarks of one face: dlib's shape predictor (float leaves, as Debian's model file holds them)
// against face/quantized_shape_predictor (16-bit leaves, what the booth runs), on a FRMDB front photo, plus the
// memory each holds; and the loading of the models: converting dlib's file, mapping the cache of it, dlib's face
// detector made from its compressed string, and the whole LandmarkDetector with and without its caches. Prints
// figures; never fails on speed.
#include "common/image_io.h"
#include "fit/face/landmarks68.h"
#include "fit/face/quantized_shape_predictor.h"
#include "test_paths.h"

#include <benchmark/benchmark.h>
#include <dlib/image_processing.h>
#include <dlib/image_processing/frontal_face_detector.h>
#include <dlib/opencv/cv_image.h>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <memory>

using namespace avatarbooth;

namespace {

struct Face {
    cv::Mat grey;
    cv::Rect box;
};

const Face& face() {
    static const Face f = [] {
        Face x;
        const cv::Mat photo = readPhoto(test::sharedData() / "frmdb" / "001" / "Img_33.jpg");
        cv::cvtColor(photo, x.grey, cv::COLOR_BGR2GRAY);
        x.box = LandmarkDetector(AVATARBOOTH_DEFAULT_DLIB_MODEL).detectFaces(photo).at(0);
        return x;
    }();
    return f;
}

void BM_DlibShapePredictor(benchmark::State& state) {
    static const auto predictor = [] {
        auto p = std::make_unique<dlib::shape_predictor>();
        dlib::deserialize(AVATARBOOTH_DEFAULT_DLIB_MODEL) >> *p;
        return p;
    }();
    const Face& f = face();
    const dlib::cv_image<unsigned char> image(f.grey);
    const dlib::rectangle box(f.box.x, f.box.y, f.box.x + f.box.width - 1, f.box.y + f.box.height - 1);
    for (auto _ : state) benchmark::DoNotOptimize((*predictor)(image, box));
    // Its leaves alone (leaves x 2 coordinates per part x 4 bytes).
    state.counters["model_MB"] =
        static_cast<double>(predictor->num_features() * predictor->num_parts() * 2 * sizeof(float)) / (1024.0 * 1024.0);
}

void BM_QuantizedShapePredictor(benchmark::State& state) {
    static const QuantizedShapePredictor predictor(AVATARBOOTH_DEFAULT_DLIB_MODEL);
    const Face& f = face();
    for (auto _ : state) benchmark::DoNotOptimize(predictor.predict(f.grey, f.box));
    state.counters["model_MB"] = static_cast<double>(predictor.modelBytes()) / (1024.0 * 1024.0);
}

// A cache folder of this benchmark's own, filled once (by the first load from it).
const std::filesystem::path& cacheDir() {
    static const std::filesystem::path dir = [] {
        const std::filesystem::path d = test::scratchDir("bench_shape_predictor") / "cache";
        QuantizedShapePredictor::load(AVATARBOOTH_DEFAULT_DLIB_MODEL, d);
        LandmarkDetector(AVATARBOOTH_DEFAULT_DLIB_MODEL, d);
        return d;
    }();
    return dir;
}

// The same predictor mapped from its cache: the walk reads the file's pages instead of the converted arrays.
void BM_QuantizedShapePredictorFromCache(benchmark::State& state) {
    static const auto predictor = QuantizedShapePredictor::load(AVATARBOOTH_DEFAULT_DLIB_MODEL, cacheDir());
    const Face& f = face();
    for (auto _ : state) benchmark::DoNotOptimize(predictor->predict(f.grey, f.box));
}

void BM_LoadConvertingDlibsFile(benchmark::State& state) {
    for (auto _ : state) benchmark::DoNotOptimize(QuantizedShapePredictor(AVATARBOOTH_DEFAULT_DLIB_MODEL).parts());
}

void BM_LoadFromCache(benchmark::State& state) {
    const std::filesystem::path& dir = cacheDir();
    for (auto _ : state) {
        const auto predictor = QuantizedShapePredictor::load(AVATARBOOTH_DEFAULT_DLIB_MODEL, dir);
        if (predictor->cacheRead().empty()) state.SkipWithError("the cache was not read");
    }
}

void BM_DlibFrontalFaceDetector(benchmark::State& state) {
    for (auto _ : state) benchmark::DoNotOptimize(dlib::get_frontal_face_detector());
}

// What a fit process waits for before its first photo: the face detector and the shape predictor.
void BM_LandmarkDetectorWithoutCache(benchmark::State& state) {
    for (auto _ : state) LandmarkDetector(AVATARBOOTH_DEFAULT_DLIB_MODEL, "");
}

void BM_LandmarkDetectorFromCache(benchmark::State& state) {
    const std::filesystem::path& dir = cacheDir();
    for (auto _ : state) LandmarkDetector(AVATARBOOTH_DEFAULT_DLIB_MODEL, dir);
}

}  // namespace

BENCHMARK(BM_DlibShapePredictor)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QuantizedShapePredictor)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_QuantizedShapePredictorFromCache)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LoadConvertingDlibsFile)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LoadFromCache)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DlibFrontalFaceDetector)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LandmarkDetectorWithoutCache)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LandmarkDetectorFromCache)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
