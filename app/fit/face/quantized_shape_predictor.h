// dlib's 68-point shape predictor (an ensemble of regression trees, Kazemi and Sullivan 2014) held with its leaf
// vectors as 16-bit integers instead of 32-bit floats, in one block instead of one per leaf: the float model was a
// large share of the kiosk's peak memory (README, "Memory", has the figures, and tests/data how close its
// landmarks stay to dlib's own).
//
// Only the storage is ours: the model file is read with dlib's deserialisers (its own format, version 1), and the
// pixel features, the shape-to-image transforms and the tree walk are dlib's (dlib/image_processing/
// shape_predictor.h), called as dlib's shape_predictor::operator() calls them. Converting dlib's file takes about
// half a second of every start; load() keeps the converted trees in a cache file that later starts map instead.
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
    // The same predictor, from the cache file `cacheDir`/<model's file name>.quantized when that was made from
    // this very model file (fit/face/model_cache.h: its path, size and modification time); otherwise converted
    // from the model file, and the cache (re)written. A missing, stale, truncated or damaged cache is rebuilt; one
    // that cannot be written is logged and the converted model used. No cache with an empty `cacheDir` or a model
    // that is not a regular file (a pipe). Throws as the constructor does.
    static std::unique_ptr<const QuantizedShapePredictor> load(const std::filesystem::path& model,
                                                               const std::filesystem::path& cacheDir);
    ~QuantizedShapePredictor();
    QuantizedShapePredictor(const QuantizedShapePredictor&) = delete;
    QuantizedShapePredictor& operator=(const QuantizedShapePredictor&) = delete;

    int parts() const;
    // The landmarks inside `face` (image pixels) of an 8-bit grey image, rounded to whole pixels as dlib rounds
    // them. Thread-safe: the model is only read.
    std::vector<cv::Point> predict(const cv::Mat& grey, const cv::Rect& face) const;
    // The same before the rounding (dlib's regression gives a fraction of a pixel, which it throws away).
    std::vector<cv::Point2d> predictSubpixel(const cv::Mat& grey, const cv::Rect& face) const;
    // Bytes held by the trees (splits, leaves and their scales).
    std::size_t modelBytes() const;
    // The cache file load() read the trees from (else empty: they were converted from the model file).
    const std::filesystem::path& cacheRead() const { return cacheRead_; }

    struct Model;  // the trees, defined in the .cpp (public only so that its loading helpers can name it)

private:
    QuantizedShapePredictor(std::unique_ptr<const Model> model, std::filesystem::path cacheRead);
    std::unique_ptr<const Model> model_;
    std::filesystem::path cacheRead_;
};

}  // namespace avatarbooth
