// dlib's 68-point shape predictor (an ensemble of regression trees, Kazemi and Sullivan 2014) held with its leaf
// vectors as 16-bit integers instead of 32-bit floats, in one block instead of one per leaf: the float model was a
// large share of the kiosk's peak memory (README, "Memory", has the figures, and tests/data how close its
// landmarks stay to dlib's own).
//
// Only the storage is ours: the model file is read with dlib's deserialisers (its own format, version 1), and the
// pixel features, the shape-to-image transforms and the tree walk are dlib's (dlib/image_processing/
// shape_predictor.h), called as dlib's shape_predictor::operator() calls them.
#pragma once

#include <opencv2/core.hpp>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

namespace avatarbooth {

class QuantizedShapePredictor {
public:
    // Reads a dlib shape predictor file (e.g. shape_predictor_68_face_landmarks.dat), one tree at a time so that
    // the float model is never held whole. Throws BoothError(BadConfig) naming the file when it cannot be read or
    // is not a dlib shape predictor.
    explicit QuantizedShapePredictor(const std::filesystem::path& model);
    ~QuantizedShapePredictor();
    QuantizedShapePredictor(const QuantizedShapePredictor&) = delete;
    QuantizedShapePredictor& operator=(const QuantizedShapePredictor&) = delete;

    int parts() const;
    // The landmarks inside `face` (image pixels) of an 8-bit grey image, rounded to whole pixels as dlib rounds
    // them. Thread-safe: the model is only read.
    std::vector<cv::Point> predict(const cv::Mat& grey, const cv::Rect& face) const;
    // Bytes held by the trees (splits, leaves and their scales).
    std::size_t modelBytes() const;

    struct Model;  // the trees, defined in the .cpp (public only so that its loading helpers can name it)

private:
    std::unique_ptr<const Model> model_;
};

}  // namespace avatarbooth
