// dlib's HOG frontal face detector and 68-point shape predictor (the only landmark model Debian ships:
// libdlib-data, trained on iBUG 300-W, whose terms exclude commercial use — the path is configurable).
#include "fit/face/landmarks68.h"

#include "common/error.h"
#include "fit/face/model_cache.h"
#include "fit/face/quantized_shape_predictor.h"

#include <dlib/image_processing.h>
#include <dlib/image_processing/frontal_face_detector.h>
#include <dlib/opencv/cv_image.h>
#include <dlib/revision.h>
#include <opencv2/imgproc.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <sstream>

namespace avatarbooth {

struct LandmarkDetector::Impl {
    dlib::frontal_face_detector detector;
    // dlib's model with 16-bit leaves (face/quantized_shape_predictor.h): half the memory of dlib's own.
    std::shared_ptr<const QuantizedShapePredictor> predictor;

    // Face boxes in full-image pixels, largest first.
    std::vector<cv::Rect> faces(const cv::Mat& fullGrey);
    // The 68 points inside a face box.
    std::array<cv::Point2d, 68> landmarks(const cv::Mat& grey, const cv::Rect& face) {
        // Unrounded: dlib rounds its points to whole pixels, half a pixel of noise the fit need not have.
        const std::vector<cv::Point2d> shape = predictor->predictSubpixel(grey, face);
        std::array<cv::Point2d, 68> points{};
        for (unsigned k = 0; k < 68; ++k) points[k] = shape[k];
        return points;
    }
};

namespace {

cv::Mat toGrey(const cv::Mat& bgr) {
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    return grey;
}

// dlib makes its face detector by decompressing a string compiled into it, a quarter of a second of every start;
// the detector's own serialisation (155 KB) reads in milliseconds. It depends only on dlib's version.
dlib::frontal_face_detector frontalFaceDetector(const std::filesystem::path& cacheDir) {
    if (cacheDir.empty()) return dlib::get_frontal_face_detector();
    static constexpr CacheKind kKind{"face-detector", 1};
    const std::string stamp = "dlib " + std::to_string(DLIB_MAJOR_VERSION) + "." + std::to_string(DLIB_MINOR_VERSION) +
                              "." + std::to_string(DLIB_PATCH_VERSION) + " get_frontal_face_detector()";
    const std::filesystem::path file = cacheDir / "frontal_face_detector.dlib";
    std::string why;
    if (const auto cache = CacheFile::open(file, kKind, stamp, why)) {
        try {
            const auto payload = cache->payload();
            std::istringstream in(std::string(reinterpret_cast<const char*>(payload.data()), payload.size()));
            dlib::frontal_face_detector detector;
            dlib::deserialize(detector, in);
            return detector;
        } catch (const dlib::serialization_error& e) {
            why = std::string("is not a detector dlib reads: ") + e.what();
        }
    }
    if (!why.empty()) spdlog::info("{}: {}: making dlib's face detector again", file.string(), why);
    dlib::frontal_face_detector detector = dlib::get_frontal_face_detector();
    std::ostringstream out;
    dlib::serialize(detector, out);
    try {
        const std::string bytes = out.str();
        const std::string_view pieces[] = {bytes};
        CacheFile::write(file, kKind, stamp, pieces);
    } catch (const BoothError& e) {
        spdlog::warn("face detector cache not written, so it is made again at every start: {}", e.what());
    }
    return detector;
}

}  // namespace

LandmarkDetector::LandmarkDetector(const std::filesystem::path& model)
    : LandmarkDetector(model, defaultModelCacheDir()) {}

LandmarkDetector::LandmarkDetector(const std::filesystem::path& model, const std::filesystem::path& cacheDir)
    : impl_(std::make_unique<Impl>()) {
    impl_->detector = frontalFaceDetector(cacheDir);
    // Any readable file that is not a folder: a named pipe too (the kiosk's tests feed a model slowly, or never,
    // through one, to check that the booth does not wait for the load).
    if (!std::filesystem::exists(model) || std::filesystem::is_directory(model))
        throw BoothError(ErrorKind::BadConfig, model.string(),
                         "landmark model not found (install Debian's libdlib-data, or set [face] landmark_model)");
    std::shared_ptr<const QuantizedShapePredictor> predictor = QuantizedShapePredictor::load(model, cacheDir);
    if (predictor->parts() != 68)
        throw BoothError(ErrorKind::BadConfig, model.string(),
                         "has " + std::to_string(predictor->parts()) + " landmarks, 68 expected");
    impl_->predictor = std::move(predictor);
}

LandmarkDetector::LandmarkDetector(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

LandmarkDetector::~LandmarkDetector() = default;

std::unique_ptr<LandmarkDetector> LandmarkDetector::sharingModel() const {
    auto impl = std::make_unique<Impl>();
    impl->detector = impl_->detector;  // a copy of the trained detector: cheaper than reading it again
    impl->predictor = impl_->predictor;
    return std::unique_ptr<LandmarkDetector>(new LandmarkDetector(std::move(impl)));
}

std::vector<cv::Rect> LandmarkDetector::Impl::faces(const cv::Mat& fullGrey) {
    // HOG detection costs grow with the pixel count; 640 px keeps a booth face (>= 150 px) well above dlib's
    // 80 px minimum, and small photos are upsampled once so that small faces are still found.
    constexpr int kMaxSide = 640;
    const double scale = std::min(1.0, static_cast<double>(kMaxSide) / std::max(fullGrey.cols, fullGrey.rows));
    cv::Mat grey = fullGrey;
    if (scale < 1.0) cv::resize(grey, grey, cv::Size(), scale, scale, cv::INTER_AREA);
    double detectScale = scale;
    if (std::max(grey.cols, grey.rows) < 500) {
        cv::resize(grey, grey, cv::Size(), 2.0, 2.0, cv::INTER_LINEAR);
        detectScale *= 2.0;
    }
    const std::vector<dlib::rectangle> found = detector(dlib::cv_image<unsigned char>(grey));
    std::vector<cv::Rect> boxes;
    for (const auto& r : found) {
        boxes.emplace_back(cv::Point(static_cast<int>(std::lround(static_cast<double>(r.left()) / detectScale)),
                                     static_cast<int>(std::lround(static_cast<double>(r.top()) / detectScale))),
                           cv::Point(static_cast<int>(std::lround(static_cast<double>(r.right() + 1) / detectScale)),
                                     static_cast<int>(std::lround(static_cast<double>(r.bottom() + 1) / detectScale))));
    }
    std::sort(boxes.begin(), boxes.end(), [](const cv::Rect& a, const cv::Rect& b) { return a.area() > b.area(); });
    return boxes;
}

std::vector<cv::Rect> LandmarkDetector::detectFaces(const cv::Mat& bgr) const { return impl_->faces(toGrey(bgr)); }

std::array<cv::Point2d, 68> LandmarkDetector::landmarksIn(const cv::Mat& bgr, const cv::Rect& face) const {
    return impl_->landmarks(toGrey(bgr), face);
}

FaceLandmarks LandmarkDetector::detect(const cv::Mat& bgr) const {
    const cv::Mat grey = toGrey(bgr);  // once, for both the detector and the predictor
    const std::vector<cv::Rect> faces = impl_->faces(grey);
    if (faces.empty()) throw BoothError(ErrorKind::NoFace, "", "no face found (is the face in view, lit and frontal?)");
    FaceLandmarks result;
    result.face = faces.front();
    result.facesFound = static_cast<int>(faces.size());
    result.points = impl_->landmarks(grey, result.face);
    return result;
}

}  // namespace avatarbooth
