// Synthetic visitor: warp, face paint, photos, ground truth.
#include "sim/synthetic_visitor.h"

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/image_io.h"
#include "fit/export/glb.h"
#include "fit/face/landmarks68.h"
#include "fit/head/surface_texels.h"

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include <array>
#include <cmath>
#include <random>

namespace avatarbooth {
namespace {

constexpr double kPi = 3.14159265358979323846;

double sigmoid(double t) { return 1.0 / (1.0 + std::exp(-t)); }

struct WarpCoefficients {
    double width = 1, height = 1, depth = 1, jaw = 0, nose = 0, backOfHead = 0, chin = 0;
};

WarpCoefficients coefficientsFor(unsigned seed) {
    WarpCoefficients c;
    if (seed == 0) return c;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    c.width = 1.0 + 0.07 * u(rng);
    c.height = 1.0 + 0.06 * u(rng);
    c.depth = 1.0 + 0.06 * u(rng);
    c.jaw = 0.09 * u(rng);
    c.nose = 5.0 * u(rng);
    c.backOfHead = 8.0 * u(rng);
    c.chin = 6.0 * u(rng);
    return c;
}

glm::dvec3 faceCentre(const BaseHead& base, int from, int to) {
    glm::dvec3 sum(0.0);
    for (int k = from; k <= to; ++k) sum += base.mesh.positions[base.frontFeatures.at(landmarkName(k))];
    return sum / static_cast<double>(to - from + 1);
}

glm::dvec2 xy(const glm::dvec3& p) { return {p.x, p.y}; }

double distanceToSegment(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b) {
    const glm::dvec2 ab = b - a;
    const double t = std::clamp(glm::dot(p - a, ab) / std::max(glm::dot(ab, ab), 1e-12), 0.0, 1.0);
    return glm::distance(p, a + t * ab);
}

// Hair covers the head above this height, by the angle around the vertical axis (0 = the face, 180 = the back).
double hairlineHeight(double azimuthDeg) {
    static const double kAngles[] = {0, 50, 80, 100, 140, 180};
    static const double kHeights[] = {74, 60, 32, 26, -25, -48};
    const double a = std::abs(azimuthDeg);
    for (int i = 0; i < 5; ++i)
        if (a <= kAngles[i + 1]) {
            const double t = (a - kAngles[i]) / (kAngles[i + 1] - kAngles[i]);
            return kHeights[i] + t * (kHeights[i + 1] - kHeights[i]);
        }
    return kHeights[5];
}

cv::Vec3d mix(const cv::Vec3d& a, const cv::Vec3d& b, double t) { return a * (1.0 - t) + b * t; }

}  // namespace

glm::dvec3 syntheticWarp(const glm::dvec3& p, unsigned seed) {
    const WarpCoefficients c = coefficientsFor(seed);
    const double faceFront = sigmoid((p.z - 40.0) / 10.0);
    glm::dvec3 q;
    q.x = p.x * c.width * (1.0 + c.jaw * sigmoid(-(p.y + 55.0) / 18.0));
    q.y = p.y * c.height - c.chin * std::exp(-p.x * p.x / (2.0 * 40.0 * 40.0)) * faceFront * sigmoid(-(p.y + 70.0) / 12.0);
    q.z = p.z * c.depth +
          c.nose * std::exp(-p.x * p.x / (2.0 * 14.0 * 14.0) - (p.y + 28.0) * (p.y + 28.0) / (2.0 * 20.0 * 20.0)) *
              sigmoid((p.z - 70.0) / 6.0) -
          c.backOfHead * sigmoid(-(p.z + 40.0) / 15.0) * sigmoid((p.y + 10.0) / 20.0);
    return q;
}

cv::Mat paintSyntheticFace(const BaseHead& base, int textureSize) {
    const Mesh& mesh = base.mesh;
    const SurfaceTexels texels = sampleSurfaceTexels(mesh, mesh.vertexNormals(), cv::Size(textureSize, textureSize));
    std::array<glm::dvec3, 68> landmarks;  // looked up once: the texel loop below runs a million times
    for (int k = 0; k < 68; ++k) landmarks[static_cast<std::size_t>(k)] = mesh.positions[base.frontFeatures.at(landmarkName(k))];
    const auto at = [&](int k) { return landmarks[static_cast<std::size_t>(k)]; };
    const glm::dvec3 rightEye = faceCentre(base, 36, 41), leftEye = faceCentre(base, 42, 47);
    const double eyeHalfWidth = 0.5 * glm::distance(xy(at(36)), xy(at(39)));
    const glm::dvec3 mouth = faceCentre(base, 48, 59);
    const double mouthHalfWidth = 0.5 * glm::distance(xy(at(48)), xy(at(54)));
    const double faceDepth = base.eyeMidpoint().z - 35.0;  // texels in front of this belong to the face

    const cv::Vec3d skin(128, 158, 206), skinShadow(110, 135, 185), hair(28, 38, 58), brow(35, 45, 65);
    const cv::Vec3d sclera(222, 228, 232), iris(55, 85, 120), pupil(18, 18, 22), lash(25, 25, 35);
    const cv::Vec3d lip(92, 92, 172), lipLine(45, 45, 95), nostril(40, 50, 85);
    std::mt19937 rng(7);
    std::normal_distribution<double> grain(0.0, 3.0);
    cv::Mat texture = paintTexels(texels, [&](const glm::dvec3& p, const cv::Vec3f& nf) {
        const glm::dvec2 q(p.x, p.y);
        const bool onFace = p.z > faceDepth && nf[2] > 0.25;
        // Skin with a gentle low-frequency variation (blotches) so the surface is not flat colour.
        cv::Vec3d colour = mix(skin, skinShadow, 0.5 + 0.5 * std::sin(p.x * 0.09) * std::sin(p.y * 0.07 + p.z * 0.05));
        const double azimuth = std::atan2(p.x, p.z) * 180.0 / kPi;
        const bool ear = std::abs(p.x) > 70.0 && p.y > -40.0 && p.y < 28.0 && p.z > -30.0 && p.z < 14.0;
        const double hairTop = hairlineHeight(azimuth);
        if (!ear && p.y > hairTop) colour = mix(colour, hair, std::min(1.0, (p.y - hairTop) / 4.0));
        if (onFace) {
            // Brows: a thick stroke along 17-21 and 22-26.
            for (const int start : {17, 22})
                for (int k = start; k < start + 4; ++k)
                    if (distanceToSegment(q, xy(at(k)), xy(at(k + 1))) < 3.2) colour = brow;
            // Eyes: an almond of the eye's width, iris, pupil, lash line on the upper lid.
            for (const glm::dvec3& eye : {rightEye, leftEye}) {
                const glm::dvec2 d = (q - xy(eye)) / eyeHalfWidth;
                const double lidHeight = d.y > 0 ? 0.42 : 0.36;
                const double almond = d.x * d.x + (d.y / lidHeight) * (d.y / lidHeight);
                if (almond < 1.0) {
                    const double r = glm::length(q - xy(eye));
                    colour = r < 2.4 ? pupil : (r < 5.6 ? iris : sclera);
                } else if (almond < 1.45 && d.y > 0.0) {
                    colour = lash;
                } else if (almond < 1.6 && d.y <= 0.0) {
                    colour = mix(colour, skinShadow * 0.8, 0.6);
                }
            }
            // Lips: an ellipse around the mouth, a dark line between them.
            const glm::dvec2 m = (q - xy(mouth)) / mouthHalfWidth;
            const double lipEllipse = m.x * m.x + (m.y / 0.42) * (m.y / 0.42);
            if (lipEllipse < 1.0) colour = std::abs(m.y) < 0.05 ? lipLine : lip;
            // Nostrils under the nose tip, either side of 33.
            for (const double side : {-1.0, 1.0}) {
                const glm::dvec2 n = q - (xy(at(33)) + glm::dvec2(side * 7.0, 1.5));
                if ((n.x / 3.6) * (n.x / 3.6) + (n.y / 2.0) * (n.y / 2.0) < 1.0) colour = nostril;
            }
        }
        const double g = grain(rng);
        return cv::Vec3b(cv::saturate_cast<unsigned char>(colour[0] + g), cv::saturate_cast<unsigned char>(colour[1] + g),
                         cv::saturate_cast<unsigned char>(colour[2] + g));
    });
    padTextureBorders(texture, texels.covered, 6);
    cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0.8);
    return texture;
}

namespace {

// A dark cloth backdrop: a blue-grey gradient with soft vertical folds and a little noise.
cv::Mat makeBackdrop(cv::Size size, unsigned seed) {
    cv::Mat backdrop(size, CV_8UC3);
    std::mt19937 rng(seed * 977u + 3u);
    std::uniform_real_distribution<double> phase(0.0, 2.0 * kPi);
    const double p1 = phase(rng), p2 = phase(rng);
    std::normal_distribution<double> noise(0.0, 2.0);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            const double fold = 10.0 * std::sin(x * 0.021 + p1) + 6.0 * std::sin(x * 0.047 + p2 + y * 0.004);
            const double light = 1.0 - 0.35 * std::abs(x - size.width / 2.0) / size.width - 0.2 * y / size.height;
            const double n = noise(rng);
            backdrop.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<unsigned char>((78 + fold) * light + n),
                                                     cv::saturate_cast<unsigned char>((52 + 0.6 * fold) * light + n),
                                                     cv::saturate_cast<unsigned char>((46 + 0.5 * fold) * light + n));
        }
    return backdrop;
}

// Shoulders and chest under the neck, as a polygon in head space drawn with the camera (a shirt): from just above
// where the head mesh's neck ends (the head covers the overlap), out and down past the image's bottom.
void drawShoulders(cv::Mat& image, const RenderCamera& camera, bool side, const SyntheticPhotoSetup& setup) {
    const SyntheticNeck& neck = setup.neck;
    const double y = neck.baseY, x = neck.halfWidth;
    std::vector<glm::dvec3> outline;
    if (!side) {
        outline = {{-x, y, 0},          {-x - 22, y - 40, 0}, {-185, y - 65, 0}, {-215, y - 150, 0}, {-230, -900, 0},
                   {230, -900, 0},      {215, y - 150, 0},    {185, y - 65, 0},  {x + 22, y - 40, 0}, {x, y, 0}};
    } else {
        outline = {{0, y, neck.frontZ},        {0, y - 50, neck.frontZ + 35}, {0, y - 110, neck.frontZ + 70},
                   {0, -900, neck.frontZ + 80}, {0, -900, neck.backZ - 70},   {0, y - 100, neck.backZ - 65},
                   {0, y - 40, neck.backZ - 20}, {0, y, neck.backZ}};
    }
    std::vector<std::vector<glm::dvec3>> outlines{outline};
    if (side && setup.sideYawDeg != 90.0) {
        // Turned off the profile, the shoulders' breadth shows too: the front's outline, in the plane half-way
        // between the neck's front and back, drawn as well.
        const double zMid = 0.5 * (neck.frontZ + neck.backZ);
        outlines.push_back({{-x, y, zMid}, {-x - 22, y - 40, zMid}, {-185, y - 65, zMid}, {-215, y - 150, zMid},
                            {-230, -900, zMid}, {230, -900, zMid}, {215, y - 150, zMid}, {185, y - 65, zMid},
                            {x + 22, y - 40, zMid}, {x, y, zMid}});
    }
    std::vector<std::vector<cv::Point>> polys;
    for (const auto& o : outlines) {
        std::vector<cv::Point> poly;
        for (const auto& p : o) {
            const glm::dvec2 px = camera.project(p);
            poly.emplace_back(static_cast<int>(std::lround(px.x - 0.5)), static_cast<int>(std::lround(px.y - 0.5)));
        }
        polys.push_back(std::move(poly));
    }
    for (const auto& poly : polys)
        cv::fillPoly(image, std::vector<std::vector<cv::Point>>{poly}, setup.shirt, cv::LINE_AA);
}

cv::Mat composite(const cv::Mat& backdrop, const RenderResult& head, const RenderCamera& camera, bool side,
                  const SyntheticPhotoSetup& setup) {
    cv::Mat photo = backdrop.clone();
    drawShoulders(photo, camera, side, setup);
    for (int y = 0; y < photo.rows; ++y)
        for (int x = 0; x < photo.cols; ++x) {
            const double a = head.mask.at<unsigned char>(y, x) / 255.0;
            if (a <= 0.0) continue;
            const cv::Vec3b h = head.bgr.at<cv::Vec3b>(y, x);
            cv::Vec3b& o = photo.at<cv::Vec3b>(y, x);
            // The renderer blends edges with its background colour (black here), so the colour is premultiplied.
            for (int c = 0; c < 3; ++c) o[c] = cv::saturate_cast<unsigned char>(h[c] + (1.0 - a) * o[c]);
        }
    return photo;
}

}  // namespace

void photographSyntheticHead(SyntheticVisitor& v, const BaseHead& base, const glm::dvec3& earHole, MeshRenderer& renderer,
                             const SyntheticPhotoSetup& setup) {
    const int w = setup.imageSize.width, h = setup.imageSize.height;
    v.frontCamera = RenderCamera::orthographic(setup.target + glm::dvec3(0, 0, 800), setup.target, {0, 1, 0},
                                               setup.mmPerPixel, w, h);
    const double sideSign = setup.sideNoseImageRight ? -1.0 : 1.0;  // camera on the subject's right: nose right
    // At yaw 90 exactly (x on the axis): the same camera as before the yaw was an option, to the last bit.
    const double yaw = setup.sideYawDeg * kPi / 180.0;
    const glm::dvec3 sideDir = setup.sideYawDeg == 90.0 ? glm::dvec3(sideSign, 0, 0)
                                                         : glm::dvec3(sideSign * std::sin(yaw), 0, std::cos(yaw));
    v.sideCamera = RenderCamera::orthographic(setup.target + 800.0 * sideDir, setup.target, {0, 1, 0},
                                              setup.mmPerPixel, w, h);
    v.frontCamera.background = v.sideCamera.background = cv::Scalar(0, 0, 0);
    v.frontCamera.lit = v.sideCamera.lit = setup.lit;

    if (setup.parts.empty()) {
        renderer.upload(v.truthMesh, v.texture);
    } else {
        std::vector<AvatarPart> parts{AvatarPart{"head", v.truthMesh, v.texture, AlphaMode::Opaque, 0.5}};
        parts.insert(parts.end(), setup.parts.begin(), setup.parts.end());
        renderer.upload(parts);
    }
    v.background = makeBackdrop(setup.imageSize, setup.backdropSeed);
    v.front = composite(v.background, renderer.render(v.frontCamera), v.frontCamera, false, setup);
    v.side = composite(v.background, renderer.render(v.sideCamera), v.sideCamera, true, setup);

    // OpenCV / dlib pixel convention: pixel centres at integer coordinates.
    const auto toPixel = [](const glm::dvec2& p) { return cv::Point2d(p.x - 0.5, p.y - 0.5); };
    v.frontLandmarks.clear();
    v.sideLandmarks.clear();
    for (const auto& [name, vertex] : base.frontFeatures)
        v.frontLandmarks[name] = toPixel(v.frontCamera.project(v.truthMesh.positions[vertex]));
    for (const auto& [name, vertex] : base.sideFeatures)
        v.sideLandmarks[name] = toPixel(v.sideCamera.project(v.truthMesh.positions[vertex]));
    v.sideLandmarks["ear_hole"] = toPixel(v.sideCamera.project(earHole));
}

SyntheticVisitor makeSyntheticVisitor(const BaseHead& base, MeshRenderer& renderer, const SyntheticVisitorOptions& options) {
    SyntheticVisitor v;
    v.texture = paintSyntheticFace(base, options.textureSize);
    v.truthMesh = base.mesh;
    for (auto& p : v.truthMesh.positions) p = syntheticWarp(p, options.seed);
    SyntheticPhotoSetup setup;
    setup.mmPerPixel = options.mmPerPixel;
    setup.imageSize = options.imageSize;
    setup.sideNoseImageRight = options.sideNoseImageRight;
    setup.lit = options.lit;
    setup.backdropSeed = options.seed;
    photographSyntheticHead(v, base, syntheticWarp(base.earHoleCentre, options.seed), renderer, setup);
    return v;
}

void writeSyntheticVisitorFolder(const SyntheticVisitor& v, const std::filesystem::path& dir) {
    std::filesystem::create_directories(dir / "truth");
    writeFileAtomically(dir / "front.jpg", encodeImage(v.front, ".jpg", 92));
    writeFileAtomically(dir / "side.jpg", encodeImage(v.side, ".jpg", 92));
    writeFileAtomically(dir / "background.png", encodeImage(v.background, ".png"));
    writeGlb(dir / "truth" / "head.glb", v.truthMesh, v.texture, "synthetic-visitor");
    nlohmann::json j;
    j["pixel_convention"] = "pixel centres at integer coordinates (OpenCV/dlib)";
    for (const auto& [name, p] : v.frontLandmarks) j["front"][name] = {p.x, p.y};
    for (const auto& [name, p] : v.sideLandmarks) j["side"][name] = {p.x, p.y};
    writeFileAtomically(dir / "truth" / "landmarks.json", j.dump(2) + "\n");  // last: its presence means complete
}

std::filesystem::path ensureSyntheticVisitorFolder(const std::filesystem::path& dir) {
    bool complete = true;
    for (const char* name : {"front.jpg", "side.jpg", "background.png", "truth/head.glb", "truth/landmarks.json"})
        complete = complete && std::filesystem::is_regular_file(dir / name);
    if (!complete) {
        MeshRenderer renderer;
        writeSyntheticVisitorFolder(makeSyntheticVisitor(builtinBaseHead(), renderer, SyntheticVisitorOptions{}), dir);
    }
    return dir;
}

}  // namespace avatarbooth
