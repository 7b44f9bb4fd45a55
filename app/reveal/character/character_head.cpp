// The character avatar: MakeHuman's modifiers solved for the target proportions, measured like a photo; a flat
// toon texture.
#include "reveal/character/character_head.h"

#include "reveal/character/character_modifiers.h"
#include "common/error.h"
#include "common/image_io.h"
#include "common/landmark_names.h"
#include "fit/head/surface_texels.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <filesystem>
#include <cmath>
#include <limits>

namespace avatarbooth {
namespace {

constexpr double kPi = 3.14159265358979323846;

glm::dvec2 xy(const glm::dvec3& p) { return {p.x, p.y}; }
double distanceToSegment(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b) {
    const glm::dvec2 ab = b - a;
    const double t = std::clamp(glm::dot(p - a, ab) / std::max(glm::dot(ab, ab), 1e-12), 0.0, 1.0);
    return glm::distance(p, a + t * ab);
}

glm::dvec3 feature(const Mesh& mesh, const BaseHead& base, int k) {
    return mesh.positions[base.frontFeatures.at(landmarkName(k))];
}

glm::dvec3 featureMean(const Mesh& mesh, const BaseHead& base, int from, int to) {
    glm::dvec3 sum(0.0);
    for (int k = from; k <= to; ++k) sum += feature(mesh, base, k);
    return sum / static_cast<double>(to - from + 1);
}

}  // namespace

MeshFrontView frontViewOf(const Mesh& mesh, const BaseHead& features, const glm::dvec3& earHole, double pxPerMm) {
    glm::dvec3 lo, hi;
    mesh.bounds(lo, hi);
    constexpr double margin = 10.0;
    MeshFrontView view;
    view.pxPerMm = pxPerMm;
    view.originMm = {lo.x - margin, hi.y + margin};
    const int width = static_cast<int>(std::ceil((hi.x - lo.x + 2.0 * margin) * pxPerMm));
    const int height = static_cast<int>(std::ceil((hi.y - lo.y + 2.0 * margin) * pxPerMm));
    view.input.mask = cv::Mat::zeros(height, width, CV_8U);
    constexpr int shift = 4;  // sub-pixel vertex positions for fillConvexPoly
    for (const auto& t : mesh.triangles) {
        std::array<cv::Point, 3> corners;
        for (int c = 0; c < 3; ++c) {
            const cv::Point2d px = view.toPixel(xy(mesh.positions[t[c]]));
            corners[static_cast<std::size_t>(c)] =
                cv::Point(static_cast<int>(std::lround(px.x * (1 << shift))), static_cast<int>(std::lround(px.y * (1 << shift))));
        }
        cv::fillConvexPoly(view.input.mask, corners.data(), 3, cv::Scalar(255), cv::LINE_8, shift);
    }
    for (int k = 0; k < 68; ++k)
        view.input.landmarks[static_cast<std::size_t>(k)] = view.toPixel(xy(feature(mesh, features, k)));
    view.input.earHole = view.toPixel(xy(earHole));
    return view;
}

MeasuredHead measureHead(const Mesh& mesh, const BaseHead& features, const glm::dvec3& earHole, double pxPerMm) {
    MeasuredHead out;
    out.view = frontViewOf(mesh, features, earHole, pxPerMm);
    out.mapping = mapNaritaPoints(out.view.input);
    out.proportions = computeProportions(out.mapping.points);
    return out;
}

CharacterHead makeCharacterHead(const BaseHead& base, const CharacterProportions& wanted,
                                const CharacterSettings& settings, const CharacterLook& look) {
    if (settings.correctionRounds < 1 || settings.pxPerMm <= 0.0 || settings.textureSize < 16)
        throw BoothError(ErrorKind::BadConfig, "character", "correction rounds, resolution or texture size out of range");
    CharacterHead out;
    out.mesh = base.mesh;
    out.earHole = base.earHoleCentre;
    try {
        out.base = measureHead(base.mesh, base, base.earHoleCentre, settings.pxPerMm).proportions;
    } catch (const BoothError& e) {
        throw BoothError(ErrorKind::Internal, "base head", std::string("cannot be measured for the character: ") + e.what());
    }
    CharacterProportions target = wanted;
    for (const SliderRange& s : sliderRanges()) {
        const double b = proportionQuantity(out.base, s.quantity);
        const bool applied = !settings.sliders || settings.sliders->count(std::string(s.key)) > 0;
        setProportionQuantity(target, s.quantity,
                              applied ? b + settings.exaggeration * (proportionQuantity(wanted, s.quantity) - b) : b);
    }
    out.target = target = clampToSliderRanges(target);
    out.texture = paintCharacterTexture(base, settings.textureSize, look, base.modifiers ? makeHumanToonSkin() : cv::Mat());
    if (!base.modifiers) {
        out.achieved = out.base;
        static const std::string kNoBasis = "the base head has no modifier basis: the character keeps its proportions";
        out.warnings.push_back(kNoBasis);
        return out;
    }

    const ModifierBasis& basis = *base.modifiers;
    CharacterModel model = characterModelOf(base, settings.pxPerMm);
    const auto misfit = [&](const CharacterProportions& p) {
        double sum = 0.0;
        const QuantityVector q = quantitiesOf(p), t = quantitiesOf(target);
        for (std::size_t i = 0; i < kCharacterQuantities; ++i) {
            const double d = (q[i] - t[i]) / (sliderRanges()[i].hi - sliderRanges()[i].lo);
            sum += d * d;
        }
        return sum;
    };
    // Gauss-Newton over the weights: each round a bounded least-squares step with the Jacobian where the head is,
    // halved while the head it gives measures worse (the silhouette's measures are not smooth: an ear's notch can
    // jump).
    std::vector<double> weights(model.jacobian.size(), 0.0);
    CharacterProportions now = model.base;
    for (int round = 0; round < settings.correctionRounds; ++round) {
        if (round > 0) remeasureJacobian(model, base, weights, now);
        const std::vector<double> full = solveCharacterStep(model, weights, now, target);
        bool better = false;
        for (double t = 1.0; t >= 1.0 / 16.0 && !better; t *= 0.5) {
            std::vector<double> next(weights.size());
            for (std::size_t c = 0; c < next.size(); ++c) next[c] = weights[c] + t * (full[c] - weights[c]);
            const CharacterProportions measured = measureCharacter(model, base, next);
            if (misfit(measured) < misfit(now)) {
                weights = next;
                now = measured;
                better = true;
            }
        }
        if (!better) break;
    }
    const CharacterShape shape = characterShape(model, base, weights);
    out.mesh.positions = shape.positions;
    out.earHole = shape.earHole;
    out.achieved = now;
    const std::vector<double> all = basisWeights(model, basis.modifiers.size(), weights);
    for (const auto& ks : model.controlModifiers)
        for (const std::size_t k : ks) out.modifiers.emplace_back(basis.modifiers[k].name, all[k]);
    return out;
}

const cv::Mat& makeHumanToonSkin() {
    static const cv::Mat skin = [] {
        const std::filesystem::path dir = findMakeHumanBaseHead();
        const std::filesystem::path file = dir / "skins" / "toon01.jpg";
        if (dir.empty() || !std::filesystem::is_regular_file(file)) return cv::Mat();
        return readPhoto(file);
    }();
    return skin;
}

cv::Mat paintCharacterTexture(const BaseHead& base, int textureSize, const CharacterLook& look, const cv::Mat& toonSkin) {
    const Mesh& mesh = base.mesh;
    const SurfaceTexels texels = sampleSurfaceTexels(mesh, mesh.vertexNormals(), cv::Size(textureSize, textureSize));
    std::array<glm::dvec2, 68> lm;
    for (int k = 0; k < 68; ++k) lm[static_cast<std::size_t>(k)] = xy(feature(mesh, base, k));
    const auto at = [&](int k) { return lm[static_cast<std::size_t>(k)]; };
    const auto meanOf = [&](int from, int to) {
        glm::dvec2 s(0.0);
        for (int k = from; k <= to; ++k) s += at(k);
        return s / static_cast<double>(to - from + 1);
    };
    const std::array<glm::dvec2, 2> eyes = {meanOf(36, 41), meanOf(42, 47)};
    const double eyeHalf = 0.5 * glm::distance(at(36), at(39));
    const double eyeDistance = glm::distance(eyes[0], eyes[1]);
    const glm::dvec2 mouth = 0.5 * (at(62) + at(66));
    const double mouthHalf = 0.5 * glm::distance(at(48), at(54));
    const double browLine = meanOf(17, 26).y;
    const double faceDepth = featureMean(mesh, base, 36, 47).z - 0.55 * eyeDistance;
    const double earX = 1.1 * glm::distance(eyes[0], eyes[1]);  // beyond this the side of the head: ears, hair

    const auto colour = [](const cv::Scalar& s) { return cv::Vec3b(cv::saturate_cast<unsigned char>(s[0]),
                                                                   cv::saturate_cast<unsigned char>(s[1]),
                                                                   cv::saturate_cast<unsigned char>(s[2])); };
    const cv::Vec3b skin = colour(look.skin), hair = colour(look.hair), iris = colour(look.iris), lips = colour(look.lips);
    const cv::Vec3b white(250, 250, 250), ink(30, 25, 30), brow = colour(look.hair * 0.7);
    const cv::Vec3b blush = colour(look.skin * 0.6 + cv::Scalar(90, 90, 255) * 0.4), mouthLine = colour(look.lips * 0.55);

    // The skin layer: toon01 on the head's UVs tinted by the skin colour (a plain white toon01 gives the skin itself).
    cv::Mat toon;
    if (!toonSkin.empty()) cv::resize(toonSkin, toon, cv::Size(textureSize, textureSize), 0.0, 0.0, cv::INTER_AREA);
    const auto skinAt = [&](int x, int y) {
        if (toon.empty()) return skin;
        const cv::Vec3b t = toon.at<cv::Vec3b>(y, x);
        cv::Vec3b out;
        for (int ch = 0; ch < 3; ++ch) out[ch] = cv::saturate_cast<unsigned char>(t[ch] * look.skin[ch] / 255.0);
        return out;
    };
    const auto paint = [&](const glm::dvec3& p, const cv::Vec3f& nf, const cv::Vec3b& skinHere) {
        const glm::dvec2 q(p.x, p.y);
        cv::Vec3b c = skinHere;
        // Hair: a cap whose edge is high on the forehead, comes down over the temples above the ears and to the
        // nape at the back (by the direction around the head, 0 = the face).
        const double azimuth = std::abs(std::atan2(p.x, p.z)) * 180.0 / kPi;
        const double front = browLine + 0.75 * eyeDistance, temple = browLine - 0.05 * eyeDistance,
                     back = browLine - 1.2 * eyeDistance;
        const double hairline = azimuth < 30.0 ? front
                          : azimuth < 80.0 ? front + (temple - front) * (azimuth - 30.0) / 50.0
                          : azimuth < 120.0 ? temple
                          : azimuth < 160.0 ? temple + (back - temple) * (azimuth - 120.0) / 40.0
                                            : back;
        const bool ear = std::abs(p.x) > earX && p.y < browLine && p.y > browLine - 1.3 * eyeDistance &&
                         p.z > -0.55 * eyeDistance && p.z < 0.3 * eyeDistance;
        if (!ear && p.y > hairline) c = hair;
        if (p.z > faceDepth && nf[2] > 0.2f) {
            for (std::size_t side = 0; side < 2; ++side) {
                // Blush under each eye.
                const glm::dvec2 cheek = eyes[side] + glm::dvec2(side == 0 ? -0.05 : 0.05, -0.55) * eyeDistance;
                const glm::dvec2 b = (q - cheek) / glm::dvec2(0.22 * eyeDistance, 0.12 * eyeDistance);
                if (glm::dot(b, b) < 1.0) c = blush;
                // Brows: a thick stroke.
                for (int k = side == 0 ? 17 : 22; k < (side == 0 ? 21 : 26); ++k)
                    if (distanceToSegment(q, at(k), at(k + 1)) < 0.05 * eyeDistance) c = brow;
                // Eyes: a tall almond, a big iris with a pupil and a highlight, an ink line on the upper lid.
                const glm::dvec2 d = (q - eyes[side]) / eyeHalf;
                const double lid = d.y > 0.0 ? 0.62 : 0.5;
                const double almond = d.x * d.x + (d.y / lid) * (d.y / lid);
                if (almond < 1.0) {
                    const glm::dvec2 r = q - eyes[side];
                    const glm::dvec2 shine = r - glm::dvec2(0.2, 0.22) * eyeHalf;
                    c = glm::length(shine) < 0.14 * eyeHalf ? white
                        : glm::length(r) < 0.22 * eyeHalf ? ink
                        : (r.x / 0.5) * (r.x / 0.5) + (r.y / 0.6) * (r.y / 0.6) < eyeHalf * eyeHalf ? iris
                                                                                          : white;
                } else if (almond < 1.5 && d.y > 0.05) {
                    c = ink;
                }
            }
            // Mouth: small lips and a dark line between them.
            const glm::dvec2 mm = (q - mouth) / mouthHalf;
            const double lipShape = mm.x * mm.x + (mm.y / 0.32) * (mm.y / 0.32);
            if (lipShape < 0.7) c = std::abs(mm.y) < 0.05 ? mouthLine : lips;
        }
        return c;
    };
    cv::Mat texture(texels.covered.size(), CV_8UC3, cv::Scalar(0, 0, 0));
    for (int y = 0; y < texture.rows; ++y)
        for (int x = 0; x < texture.cols; ++x) {
            if (!texels.covered.at<unsigned char>(y, x)) continue;
            const cv::Vec3f pf = texels.position.at<cv::Vec3f>(y, x);
            texture.at<cv::Vec3b>(y, x) = paint(glm::dvec3(pf[0], pf[1], pf[2]), texels.normal.at<cv::Vec3f>(y, x), skinAt(x, y));
        }
    padTextureBorders(texture, texels.covered, 6);
    return texture;
}

CharacterLook lookFromPhoto(const cv::Mat& bgr, const std::array<cv::Point2d, 68>& p, const cv::Mat& mask) {
    CharacterLook look;
    if (bgr.empty() || bgr.type() != CV_8UC3) return look;
    const auto at = [&](int k) { return p[static_cast<std::size_t>(k)]; };
    const double eyeDistance = cv::norm(0.5 * (at(36) + at(39)) - 0.5 * (at(42) + at(45)));
    const auto median = [](std::vector<cv::Vec3b>& px) {
        cv::Scalar out;
        for (int ch = 0; ch < 3; ++ch) {
            std::nth_element(px.begin(), px.begin() + static_cast<std::ptrdiff_t>(px.size() / 2), px.end(),
                             [ch](const cv::Vec3b& a, const cv::Vec3b& b) { return a[ch] < b[ch]; });
            out[ch] = px[px.size() / 2][ch];
        }
        return out;
    };
    const auto sampleDisc = [&](cv::Point2d c, double r, std::vector<cv::Vec3b>& px, bool needMask) {
        for (int y = static_cast<int>(c.y - r); y <= static_cast<int>(c.y + r); ++y)
            for (int x = static_cast<int>(c.x - r); x <= static_cast<int>(c.x + r); ++x) {
                if (x < 0 || y < 0 || x >= bgr.cols || y >= bgr.rows) continue;
                if ((x - c.x) * (x - c.x) + (y - c.y) * (y - c.y) > r * r) continue;
                if (needMask && (mask.empty() || mask.at<unsigned char>(y, x) == 0)) continue;
                px.push_back(bgr.at<cv::Vec3b>(y, x));
            }
    };
    std::vector<cv::Vec3b> skin;
    sampleDisc(0.5 * (at(41) + at(48)), 0.12 * eyeDistance, skin, false);
    sampleDisc(0.5 * (at(46) + at(54)), 0.12 * eyeDistance, skin, false);
    if (skin.size() > 10) look.skin = median(skin);
    // The top of the head: along the face's midline, above the brows.
    cv::Point2d brow(0.0, 0.0);
    for (int k = 17; k <= 26; ++k) brow += at(k) * 0.1;
    const cv::Point2d up = (brow - at(33));
    std::vector<cv::Vec3b> hair;
    for (double t = 1.2; t <= 1.5; t += 0.05) sampleDisc(brow + t * up, 0.15 * eyeDistance, hair, true);
    if (hair.size() > 10) look.hair = median(hair);
    return look;
}

}  // namespace avatarbooth
