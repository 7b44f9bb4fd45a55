// Front-photo face detection and dlib's 68-point landmarks (iBUG 300-W order), kept behind this small interface
// so that dlib's heavy headers stay in one source file.
#pragma once

#include "common/landmark_names.h"

#include <opencv2/core.hpp>

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace avatarbooth {

struct FaceLandmarks {
    cv::Rect face;                          // the detector's box, in image pixels
    std::array<cv::Point2d, 68> points{};   // iBUG order: jaw 0-16, brows 17-26, nose 27-35, eyes 36-47, mouth 48-67
    int facesFound = 0;                     // how many faces the detector saw (the largest is used)
};

class LandmarkDetector {
public:
    // Loads dlib's HOG face detector and the shape predictor model (a 100 MB file, held in 33 MB), both through
    // their cache files in `cacheDir` (fit/face/model_cache.h; made at the first start, when the load takes about
    // a second; empty: no cache), or defaultModelCacheDir() in the first form. Do it once.
    // Throws BoothError(BadConfig) naming the model file when it is missing or unreadable.
    explicit LandmarkDetector(const std::filesystem::path& shapePredictorModel);
    LandmarkDetector(const std::filesystem::path& shapePredictorModel, const std::filesystem::path& cacheDir);
    ~LandmarkDetector();
    LandmarkDetector(const LandmarkDetector&) = delete;
    LandmarkDetector& operator=(const LandmarkDetector&) = delete;

    // Face boxes in image pixels, largest first (detection runs on a copy scaled to at most 640 px).
    std::vector<cv::Rect> detectFaces(const cv::Mat& bgr) const;
    // The 68 points of the largest face; throws BoothError(NoFace) when there is none.
    FaceLandmarks detect(const cv::Mat& bgr) const;
    // The 68 points inside a given face box.
    std::array<cv::Point2d, 68> landmarksIn(const cv::Mat& bgr, const cv::Rect& face) const;

    // A detector for another thread, sharing this one's loaded shape predictor (read-only after loading: dlib's
    // shape_predictor::operator() is const) but with a face detector of its own: dlib's HOG detector builds its
    // image pyramid inside itself while it runs, so one detector must not serve two threads at once.
    std::unique_ptr<LandmarkDetector> sharingModel() const;

private:
    struct Impl;
    explicit LandmarkDetector(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace avatarbooth
