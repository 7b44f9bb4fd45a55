// Rendering the tile stage for the kiosk's screens: the elevation sweep, R(theta), and one render per angle.
#include "reveal/stage/stage_view.h"

#include "common/error.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <vector>

namespace avatarbooth::stage {

namespace fs = std::filesystem;

std::filesystem::path defaultStageMapFile() {
    // The same places as the strings file (StringTable::defaultFile): the two ship together.
    std::vector<fs::path> places;
    if (const char* env = std::getenv("AVATARBOOTH_ASSET_DIR"); env && *env) places.emplace_back(env);
    std::error_code ec;
    if (const fs::path exe = fs::read_symlink("/proc/self/exe", ec); !ec && !exe.empty())
        places.push_back(exe.parent_path().parent_path() / "share" / "avatarbooth");
    places.push_back(fs::path(__FILE__).parent_path().parent_path().parent_path() / "assets");  // the source tree
    places.emplace_back("/usr/share/avatarbooth");
    std::string looked;
    for (const auto& p : places) {
        if (fs::is_regular_file(p / "stage.map", ec)) return p / "stage.map";
        looked += (looked.empty() ? "" : ", ") + (p / "stage.map").string();
    }
    throw BoothError(ErrorKind::BadConfig, "stage.map", "the stage map was not found (looked at " + looked + ")");
}

double sweepElevation(double seconds, double periodSeconds, double lowDeg) {
    if (periodSeconds <= 0.0) return 45.0;
    const double phase = std::fmod(std::max(0.0, seconds), periodSeconds) / periodSeconds * 4.0;  // 0..4
    const auto ease = [](double t) { return t * t * (3.0 - 2.0 * t); };  // smoothstep: no jolt at the holds
    if (phase < 1.0) return 45.0;
    if (phase < 2.0) return 45.0 + (lowDeg - 45.0) * ease(phase - 1.0);
    if (phase < 3.0) return lowDeg;
    return lowDeg + (45.0 - lowDeg) * ease(phase - 3.0);
}

TileMap repeatAcross(const TileMap& map, int copies) {
    copies = std::max(1, copies);
    TileMap out;
    out.width = map.width * copies;
    out.height = map.height;
    const auto cells = static_cast<std::size_t>(out.width * out.height);
    out.tiles.assign(cells, Tile::Empty);
    out.cutRight.assign(cells, 0);
    out.cutBelow.assign(cells, 0);
    for (int r = 0; r < map.height; ++r)
        for (int k = 0; k < copies; ++k)
            for (int c = 0; c < map.width; ++c) {
                const auto to = static_cast<std::size_t>(r * out.width + k * map.width + c);
                out.tiles[to] = map.at(c, r);
                out.cutRight[to] = map.edgeRight(c, r) ? 1 : 0;
                out.cutBelow[to] = map.edgeBelow(c, r) ? 1 : 0;
            }
    return out;
}

int copiesToFill(const TileMap& map, double bandAspect) {
    if (map.width <= 0 || map.height <= 0 || !(bandAspect > 0.0)) return 1;
    const double aspect = static_cast<double>(map.width) / map.height;
    return std::clamp(static_cast<int>(std::lround(bandAspect / aspect)), 1, 8);
}

StageView::StageView(const Stage& stage, double tileMm, HeadlessEglContext* context) {
    // Flat-coloured boxes shown every frame while the camera sweeps, at half the band's resolution: 1 sample
    // (llvmpipe's multisampling is costly; the screen's scaling softens the edges), and the depth target is never
    // read.
    const MeshRenderer::Options options{1, false, 0};
    renderer_ = context ? std::make_unique<MeshRenderer>(*context, options) : std::make_unique<MeshRenderer>(options);
    mesh_ = stageMesh(stage, tileMm, palette_);  // (in the body: palette_ is constructed after mesh_)
    renderer_->upload(mesh_, palette_);
}

const cv::Mat& StageView::render(double elevationDeg, cv::Size size) {
    const double angle = std::round(std::clamp(elevationDeg, 0.0, 89.0) * 4.0) / 4.0;
    if (angle == angle_ && size == size_ && !image_.empty()) return image_;
    const auto t0 = std::chrono::steady_clock::now();
    // Kitamura's blend: the stage is deformed (not the camera), so upload the deformed copy.
    const glm::dmat4 blend = blendTransform(angle);
    Mesh deformed = mesh_;
    for (auto& p : deformed.positions) p = glm::dvec3(blend * glm::dvec4(p, 1.0));
    renderer_->upload(deformed, palette_);

    const double a = glm::radians(angle);
    const glm::dvec3 towardsEye(0.0, std::sin(a), std::cos(a));
    const glm::dvec3 right(1.0, 0.0, 0.0), up(0.0, std::cos(a), -std::sin(a));
    glm::dvec2 lo(1e30), hi(-1e30);
    double depthLo = 1e30, depthHi = -1e30;
    for (const auto& p : deformed.positions) {
        const glm::dvec2 q(glm::dot(p, right), glm::dot(p, up));
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
        depthLo = std::min(depthLo, glm::dot(p, towardsEye));
        depthHi = std::max(depthHi, glm::dot(p, towardsEye));
    }
    if (deformed.positions.empty()) lo = hi = glm::dvec2(0.0), depthLo = depthHi = 0.0;
    const glm::dvec2 span = glm::max(hi - lo, glm::dvec2(1.0));
    const double mmPerPixel = span.x / (size.width * 0.98);
    // The front edge (lowest point in the picture) 3 % above the bottom; the picture's centre above it.
    const double centreUp = lo.y + (size.height * 0.47) * mmPerPixel;
    const glm::dvec3 target = right * ((lo.x + hi.x) * 0.5) + up * centreUp + towardsEye * ((depthLo + depthHi) * 0.5);
    const double distance = std::max(1.0, depthHi - depthLo) * 2.0 + 100.0;
    RenderCamera camera =
        RenderCamera::orthographic(target + towardsEye * distance, target, up, mmPerPixel, size.width, size.height);
    camera.background = cv::Scalar(0, 0, 0);
    renderer_->renderBgra(camera, image_);
    angle_ = angle;
    size_ = size;
    ++renders_;
    lastMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return image_;
}

}  // namespace avatarbooth::stage
