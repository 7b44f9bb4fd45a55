// dlib's HOG frontal face detector and 68-point shape predictor (the only landmark model Debian ships:
// libdlib-data, trained on iBUG 300-W, whose terms exclude commercial use — the path is configurable).
#include "fit/face/landmarks68.h"

#include "common/error.h"
#include "fit/face/quantized_shape_predictor.h"

#include <dlib/image_processing.h>
#include <dlib/image_processing/frontal_face_detector.h>
#include <dlib/opencv/cv_image.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdio>

namespace avatarbooth {

struct LandmarkDetector::Impl {
    dlib::frontal_face_detector detector;
    // dlib's model with 16-bit leaves (face/quantized_shape_predictor.h): half the memory of dlib's own.
    std::shared_ptr<const QuantizedShapePredictor> predictor;

    // Face boxes in full-image pixels, largest first.
    std::vector<cv::Rect> faces(const cv::Mat& fullGrey);
    // The 68 points inside a face box.
    std::array<cv::Point2d, 68> landmarks(const cv::Mat& grey, const cv::Rect& face) {
        const std::vector<cv::Point> shape = predictor->predict(grey, face);
        std::array<cv::Point2d, 68> points{};
        for (unsigned k = 0; k < 68; ++k) points[k] = cv::Point2d(shape[k]);
        return points;
    }
};

namespace {

cv::Mat toGrey(const cv::Mat& bgr) {
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    return grey;
}

}  // namespace

LandmarkDetector::LandmarkDetector(const std::filesystem::path& model) : impl_(std::make_unique<Impl>()) {
    impl_->detector = dlib::get_frontal_face_detector();
    // Any readable file that is not a folder: a named pipe too (the kiosk's tests feed a model slowly, or never,
    // through one, to check that the booth does not wait for the load).
    if (!std::filesystem::exists(model) || std::filesystem::is_directory(model))
        throw BoothError(ErrorKind::BadConfig, model.string(),
                         "landmark model not found (install Debian's libdlib-data, or set [face] landmark_model)");
    auto predictor = std::make_shared<const QuantizedShapePredictor>(model);
    if (predictor->parts() != 68)
        throw BoothError(ErrorKind::BadConfig, model.string(),
                         "has " + std::to_string(predictor->parts()) + " landmarks, 68 expected");
    impl_->predictor = std::move(predictor);
}

LandmarkDetector::LandmarkDetector(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

LandmarkDetector::~LandmarkDetector() = default;

std::unique_ptr<LandmarkDetector> LandmarkDetector::sharingModel() const {
    auto impl = std::make_unique<Impl>();
    impl->detector = impl_->detector;  // a copy of the trained detector: cheaper than building it again (about 1 s)
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
