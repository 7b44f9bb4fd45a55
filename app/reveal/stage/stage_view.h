// The tile stage as the kiosk shows it: rendered from a camera whose elevation sweeps between Kitamura's top-down
// look (45 degrees, stretched by R(theta)) and an ordinary low 3-D view, with each angle rendered once and reused.
#pragma once

#include "render/mesh_renderer.h"
#include "reveal/stage/tile_stage.h"

#include <opencv2/core.hpp>

#include <filesystem>
#include <memory>

namespace avatarbooth::stage {

// The map the booth ships (app/assets/stage.map, installed next to strings.toml). Throws BoothError(BadConfig)
// listing the places looked at when it is nowhere.
std::filesystem::path defaultStageMapFile();

// The camera's elevation (degrees) `seconds` into a sweep of `periodSeconds`: a hold at 45 (the top-down look), an
// eased descent to `lowDeg`, a hold there, an eased climb back. Quarter of the period each.
double sweepElevation(double seconds, double periodSeconds, double lowDeg);

// The map repeated `copies` times side by side (edge marks included), so a map drawn for a square fills a wide band.
TileMap repeatAcross(const TileMap& map, int copies);
// How many copies of `map` fill a band of `bandAspect` (width / height) best: seen in the top-down look each map row
// is one tile high, so the map's own width / height is its picture's aspect. At least 1, at most 8.
int copiesToFill(const TileMap& map, double bandAspect);

// Not thread-safe (one GL renderer): use from one thread.
class StageView {
public:
    // `tileMm`: size of a tile in the mesh (any: the render is scaled to fit). `context`: a GL context to render
    // through (the kiosk shares one among its offscreen renders; it must outlive the view); its own when null.
    explicit StageView(const Stage& stage, double tileMm = 100.0, HeadlessEglContext* context = nullptr);

    // The stage seen from the front at elevation `elevationDeg` (0 = level, 90 = straight down), deformed by
    // blendTransform(elevation) first (R(theta) along the 45-degree diagonal). Its width fills `size` (the same scale
    // at every angle: the sweep tilts the stage, it does not zoom), its front edge stands on the bottom; what is
    // higher than the image is cut at the top. BGRA: coverage as alpha. The angle is taken to 0.25 degrees, and the image of the last angle and size
    // is kept: a held angle costs nothing.
    const cv::Mat& render(double elevationDeg, cv::Size size);

    int renders() const { return renders_; }  // how many times the GPU drew (for tests and figures)
    double lastRenderMilliseconds() const { return lastMs_; }

private:
    Mesh mesh_;
    cv::Mat palette_;
    std::unique_ptr<MeshRenderer> renderer_;
    cv::Mat image_;
    double angle_ = -1000.0;
    cv::Size size_;
    int renders_ = 0;
    double lastMs_ = 0.0;
};

}  // namespace avatarbooth::stage
