// Front, side and three-quarter previews: orthographic views framed to the mesh, lit, on grey.
#include "render/previews.h"

#include "common/error.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace avatarbooth {
namespace {

constexpr double kMargin = 0.06;                    // of the framed extent, on each side
const cv::Scalar kBackground(128, 128, 128);        // neutral grey (BGR)

// An orthographic camera looking along -direction at the mesh, fitted to the mesh's extent in that view.
RenderCamera framedCamera(const Mesh& mesh, glm::dvec3 direction, glm::dvec3 up, int size) {
    glm::dvec3 lo, hi;
    mesh.bounds(lo, hi);
    const glm::dvec3 centre = (lo + hi) * 0.5;
    const double radius = std::max(glm::length(hi - lo) * 0.5, 1.0);
    const glm::dvec3 back = glm::normalize(direction);  // from the mesh towards the camera
    const glm::dvec3 right = glm::normalize(glm::cross(up, back));
    const glm::dvec3 trueUp = glm::cross(back, right);
    double minX = std::numeric_limits<double>::max(), maxX = std::numeric_limits<double>::lowest();
    double minY = minX, maxY = maxX;
    for (const auto& p : mesh.positions) {
        const glm::dvec3 d = p - centre;
        const double x = glm::dot(d, right), y = glm::dot(d, trueUp);
        minX = std::min(minX, x);
        maxX = std::max(maxX, x);
        minY = std::min(minY, y);
        maxY = std::max(maxY, y);
    }
    const double extent = std::max({maxX - minX, maxY - minY, 1e-3});
    const glm::dvec3 target = centre + right * (0.5 * (minX + maxX)) + trueUp * (0.5 * (minY + maxY));
    const double mmPerPixel = extent * (1.0 + 2.0 * kMargin) / size;
    RenderCamera camera =
        RenderCamera::orthographic(target + back * (2.0 * radius + 100.0), target, trueUp, mmPerPixel, size, size);
    camera.background = kBackground;
    camera.lit = true;
    return camera;
}

glm::dvec3 threeQuarterDirection() {
    const double elevation = glm::radians(15.0);
    return {-std::sin(glm::radians(45.0)) * std::cos(elevation), std::sin(elevation),
            std::cos(glm::radians(45.0)) * std::cos(elevation)};
}

void checkUploaded(const MeshRenderer& renderer, const Mesh& mesh, int size) {
    if (mesh.positions.empty() || mesh.triangles.empty())
        throw BoothError(ErrorKind::Internal, "", "previews: the mesh is empty");
    if (renderer.vertexCount() != mesh.positions.size() || renderer.triangleCount() != mesh.triangles.size())
        throw BoothError(ErrorKind::Internal, "",
                         "previews: the mesh is not the one uploaded to the renderer (" +
                             std::to_string(mesh.positions.size()) + " vertices, " +
                             std::to_string(mesh.triangles.size()) + " triangles; the renderer holds " +
                             std::to_string(renderer.vertexCount()) + " and " +
                             std::to_string(renderer.triangleCount()) + ")");
    if (size <= 0) throw BoothError(ErrorKind::Internal, "", "previews: size must be positive");
}

// One view's colour picture, anti-aliased as asked.
cv::Mat renderPicture(MeshRenderer& renderer, const RenderCamera& camera, Antialias aa) {
    if (aa == Antialias::Multisample) return renderer.render(camera).bgr;
    // Each pass moves the picture by (dx, dy) pixels: a translation in clip space of 2 d / size, times w so that it
    // holds for a perspective camera too.
    static constexpr double kOffsets[4][2] = {{0.125, 0.375}, {0.375, -0.125}, {-0.125, -0.375}, {-0.375, 0.125}};
    cv::Mat sum;
    for (const auto& d : kOffsets) {
        RenderCamera shifted = camera;
        glm::dmat4 shift(1.0);
        shift[3][0] = 2.0 * d[0] / camera.width;
        shift[3][1] = 2.0 * d[1] / camera.height;
        shifted.projection = shift * camera.projection;
        const cv::Mat bgr = renderer.render(shifted).bgr;
        if (sum.empty()) sum = cv::Mat::zeros(bgr.size(), CV_16UC3);
        cv::add(sum, bgr, sum, cv::noArray(), CV_16UC3);
    }
    cv::Mat mean;
    sum.convertTo(mean, CV_8UC3, 0.25);  // rounds to nearest
    return mean;
}

}  // namespace

PreviewSet renderPreviews(MeshRenderer& renderer, const Mesh& mesh, int size, Antialias aa) {
    checkUploaded(renderer, mesh, size);
    const glm::dvec3 up(0.0, 1.0, 0.0);
    PreviewSet set;
    set.front = renderPicture(renderer, framedCamera(mesh, {0.0, 0.0, 1.0}, up, size), aa);
    set.side = renderPicture(renderer, framedCamera(mesh, {-1.0, 0.0, 0.0}, up, size), aa);
    set.threeQuarter = renderPicture(renderer, framedCamera(mesh, threeQuarterDirection(), up, size), aa);
    return set;
}

namespace {

// One mesh of all the parts, for the framing and the check that they are the ones uploaded.
Mesh allParts(const std::vector<AvatarPart>& parts) {
    Mesh all;
    for (const AvatarPart& part : parts) {
        const auto base = static_cast<std::uint32_t>(all.positions.size());
        all.positions.insert(all.positions.end(), part.mesh.positions.begin(), part.mesh.positions.end());
        for (const auto& t : part.mesh.triangles) all.triangles.push_back(t + glm::uvec3(base));
    }
    return all;
}

}  // namespace

PreviewSet renderPreviews(MeshRenderer& renderer, const std::vector<AvatarPart>& parts, int size, Antialias aa) {
    return renderPreviews(renderer, allParts(parts), size, aa);
}

void renderTurntable(MeshRenderer& renderer, const std::vector<AvatarPart>& parts, int size, int frames, Antialias aa,
                     const std::function<void(const cv::Mat&)>& each) {
    const Mesh mesh = allParts(parts);
    checkUploaded(renderer, mesh, size);
    glm::dvec3 lo, hi;
    mesh.bounds(lo, hi);
    const glm::dvec3 centre = (lo + hi) * 0.5;
    double radius = 1.0;
    for (const auto& p : mesh.positions) radius = std::max(radius, glm::length(p - centre));
    const double mmPerPixel = 2.0 * radius * (1.0 + 2.0 * kMargin) / size;
    const double elevation = glm::radians(10.0);
    for (int i = 0; i < frames; ++i) {
        const double a = 2.0 * 3.14159265358979323846 * i / frames;
        const glm::dvec3 back(-std::sin(a) * std::cos(elevation), std::sin(elevation), std::cos(a) * std::cos(elevation));
        RenderCamera camera = RenderCamera::orthographic(centre + back * (2.0 * radius + 100.0), centre,
                                                         {0.0, 1.0, 0.0}, mmPerPixel, size, size);
        camera.background = kBackground;
        camera.lit = true;
        each(renderPicture(renderer, camera, aa));
    }
}

cv::Mat renderThreeQuarterPreview(MeshRenderer& renderer, const Mesh& mesh, int size, Antialias aa) {
    checkUploaded(renderer, mesh, size);
    return renderPicture(renderer, framedCamera(mesh, threeQuarterDirection(), {0.0, 1.0, 0.0}, size), aa);
}

}  // namespace avatarbooth
