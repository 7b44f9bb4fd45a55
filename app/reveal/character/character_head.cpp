// The character avatar: measure the base head like a photo, move its parts by smooth bones towards the target
// proportions, repeat; paint a flat toon texture.
#include "reveal/character/character_head.h"

#include "common/error.h"
#include "common/landmark_names.h"
#include "fit/head/surface_texels.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

namespace avatarbooth {
namespace {

constexpr double kPi = 3.14159265358979323846;

// 1 at x <= 0, 0 at x >= 1, smooth (C1) in between.
double fadeOut(double x) {
    x = std::clamp(x, 0.0, 1.0);
    return 1.0 - x * x * (3.0 - 2.0 * x);
}
// 0 at v <= lo, 1 at v >= lo + ramp.
double fadeIn(double v, double lo, double ramp) { return 1.0 - fadeOut((v - lo) / ramp); }
// 1 inside [lo, hi], fading to 0 over `margin` outside.
double band(double v, double lo, double hi, double margin) {
    const double outside = v < lo ? lo - v : (v > hi ? v - hi : 0.0);
    return fadeOut(outside / margin);
}

glm::dvec2 xy(const glm::dvec3& p) { return {p.x, p.y}; }
glm::dvec2 rotate(const glm::dvec2& v, double radians) {
    const double c = std::cos(radians), s = std::sin(radians);
    return {c * v.x - s * v.y, s * v.x + c * v.y};
}

double distanceToSegment(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b) {
    const glm::dvec2 ab = b - a;
    const double t = std::clamp(glm::dot(p - a, ab) / std::max(glm::dot(ab, ab), 1e-12), 0.0, 1.0);
    return glm::distance(p, a + t * ab);
}

// A displacement of head space in the front plane (x, y); depth is kept.
using Bone = std::function<glm::dvec2(const glm::dvec3&)>;

// Points of a Narita mapping in millimetres (front plane).
struct PointsMm {
    std::array<glm::dvec2, 3> f;
    std::array<glm::dvec2, 10> e;
    std::array<glm::dvec2, 4> a;
    std::array<glm::dvec2, 2> b, browOuter;
    glm::dvec2 n, m;
};

PointsMm toMm(const NaritaPoints& P, const MeshFrontView& view) {
    PointsMm out;
    for (std::size_t i = 0; i < 3; ++i) out.f[i] = view.toMm(P.f[i]);
    for (std::size_t i = 0; i < 10; ++i) out.e[i] = view.toMm(P.e[i]);
    for (std::size_t i = 0; i < 4; ++i) out.a[i] = view.toMm(P.a[i]);
    for (std::size_t i = 0; i < 2; ++i) {
        out.b[i] = view.toMm(P.b[i]);
        out.browOuter[i] = view.toMm(P.browOuter[i]);
    }
    out.n = view.toMm(P.n);
    out.m = view.toMm(P.m);
    return out;
}

glm::dvec3 feature(const Mesh& mesh, const BaseHead& base, int k) {
    return mesh.positions[base.frontFeatures.at(landmarkName(k))];
}

glm::dvec3 featureMean(const Mesh& mesh, const BaseHead& base, int from, int to) {
    glm::dvec3 sum(0.0);
    for (int k = from; k <= to; ++k) sum += feature(mesh, base, k);
    return sum / static_cast<double>(to - from + 1);
}

// An elliptic part (eye, nose, mouth): inside the ellipse every point takes the part's full motion (translation
// `shift` plus the linear map `A` about the centre); outside it the motion of the nearest boundary point fades to
// nothing at `outer` ellipse radii. `outer` grows with the motion so that the fade never folds the surface (a
// smoothstep fade over a margin m folds once the displacement exceeds m / 1.5).
Bone ellipticPart(glm::dvec2 centre, double ax, double ay, glm::dvec2 shift, glm::dmat2 A, double zFront,
                  double zRamp) {
    const double linearReach = std::max(std::abs(A[0][0]) + std::abs(A[1][0]), std::abs(A[0][1]) + std::abs(A[1][1]));
    const double motion = glm::length(shift) / std::min(ax, ay) + linearReach;
    const double outer = std::max(1.8, 1.0 + 1.6 * motion);
    return [=](const glm::dvec3& p) -> glm::dvec2 {
        const double gate = fadeIn(p.z, zFront, zRamp);
        if (gate <= 0.0) return {0.0, 0.0};
        const glm::dvec2 q = xy(p) - centre;
        const double rho = std::sqrt((q.x / ax) * (q.x / ax) + (q.y / ay) * (q.y / ay));
        if (rho >= outer) return {0.0, 0.0};
        if (rho <= 1.0) return gate * (shift + A * q);
        const double fade = fadeOut((rho - 1.0) / (outer - 1.0));
        return gate * fade * (shift + A * (q / rho));
    };
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
    const double eyeDistance = glm::distance(xy(featureMean(base.mesh, base, 36, 41)), xy(featureMean(base.mesh, base, 42, 47)));

    for (int round = 0; round < settings.correctionRounds; ++round) {
        const MeasuredHead now = measureHead(out.mesh, base, out.earHole, settings.pxPerMm);
        const CharacterProportions& cur = now.proportions;
        PointsMm P = toMm(now.mapping.points, now.view);
        const double W = glm::distance(P.f[0], P.f[1]);
        const double yF = 0.5 * (P.f[0].y + P.f[1].y);

        // Face aspect: the whole head scales vertically about the face line.
        const double s = target.r[0] / cur.r[0];
        const auto scaleY = [&](double y) { return yF + (y - yF) * s; };
        for (auto& p : out.mesh.positions) p.y = scaleY(p.y);
        out.earHole.y = scaleY(out.earHole.y);
        for (auto& q : P.e) q.y = scaleY(q.y);
        for (auto& q : P.a) q.y = scaleY(q.y);
        for (std::size_t i = 0; i < 2; ++i) {
            P.b[i].y = scaleY(P.b[i].y);
            P.browOuter[i].y = scaleY(P.browOuter[i].y);
        }
        P.n.y = scaleY(P.n.y);
        P.m.y = scaleY(P.m.y);

        std::vector<Bone> bones;
        // Eyes: position along the face line (r1 and spacing), size (r2) and tilt about their centres.
        const double k = target.r[2] / cur.r[2];
        const double dTilt = (target.eyeTiltDeg - cur.eyeTiltDeg) * kPi / 180.0;
        const std::array<double, 2> alongTarget = {target.r[1] * W - 0.5 * target.eyeSpacing * W,
                                                   target.r[1] * W + 0.5 * target.eyeSpacing * W};
        for (std::size_t side = 0; side < 2; ++side) {
            glm::dvec2 c(0.0);
            for (std::size_t i = 5 * side; i < 5 * side + 5; ++i) c += P.e[i];
            c /= 5.0;
            const double angle = side == 0 ? -dTilt : dTilt;  // the right eye's outer corner is at -x
            const glm::dmat2 R(std::cos(angle), std::sin(angle), -std::sin(angle), std::cos(angle));
            const glm::dmat2 A = k * R - glm::dmat2(1.0);
            const glm::dvec2 shift(P.f[0].x + alongTarget[side] - c.x, 0.0);
            const double zEye = side == 0 ? featureMean(out.mesh, base, 36, 41).z : featureMean(out.mesh, base, 42, 47).z;
            bones.push_back(ellipticPart(c, 0.28 * eyeDistance, 0.2 * eyeDistance, shift, A, zEye - 0.5 * eyeDistance,
                                         0.2 * eyeDistance));
        }
        // Brows: the inner end's height (r5), turned about the inner end (brow tilt).
        const double dBrow = (target.browTiltDeg - cur.browTiltDeg) * kPi / 180.0;
        for (std::size_t side = 0; side < 2; ++side) {
            std::vector<glm::dvec2> line;
            for (int kk = side == 0 ? 17 : 22; kk <= (side == 0 ? 21 : 26); ++kk) {
                const glm::dvec3 v = feature(out.mesh, base, kk);
                line.emplace_back(v.x, v.y);
            }
            const double zBrow = feature(out.mesh, base, side == 0 ? 19 : 24).z;
            const glm::dvec2 inner = P.b[side];
            const double dy = yF + target.r[5] * W - inner.y;
            const double angle = side == 0 ? -dBrow : dBrow;
            const double length = glm::distance(P.b[side], P.browOuter[side]);
            const double core = 0.08 * eyeDistance;
            const double margin = std::max(0.2 * eyeDistance, 1.6 * (std::abs(dy) + std::abs(angle) * length));
            bones.push_back([=](const glm::dvec3& p) -> glm::dvec2 {
                const double gate = fadeIn(p.z, zBrow - 0.5 * eyeDistance, 0.2 * eyeDistance);
                if (gate <= 0.0) return {0.0, 0.0};
                const glm::dvec2 q = xy(p);
                double d = std::numeric_limits<double>::max();
                for (std::size_t i = 0; i + 1 < line.size(); ++i) d = std::min(d, distanceToSegment(q, line[i], line[i + 1]));
                const double w = d <= core ? 1.0 : fadeOut((d - core) / margin);
                return gate * w * (inner + rotate(q - inner, angle) - q + glm::dvec2(0.0, dy));
            });
        }
        // Nose tip (r6) and mouth (r7): vertical moves below the face line.
        const glm::dvec3 noseTip = feature(out.mesh, base, 30);
        bones.push_back(ellipticPart(P.n, 0.3 * eyeDistance, 0.2 * eyeDistance,
                                     {0.0, yF - target.r[6] * W - P.n.y}, glm::dmat2(0.0), noseTip.z - 0.8 * eyeDistance,
                                     0.2 * eyeDistance));
        const double mouthHalf = 0.5 * glm::distance(xy(feature(out.mesh, base, 48)), xy(feature(out.mesh, base, 54)));
        const double zMouth = featureMean(out.mesh, base, 48, 59).z;
        bones.push_back(ellipticPart(P.m, mouthHalf + 0.1 * eyeDistance, 0.18 * eyeDistance,
                                     {0.0, yF - target.r[7] * W - P.m.y}, glm::dmat2(0.0), zMouth - 0.6 * eyeDistance,
                                     0.2 * eyeDistance));
        // Ears: the top to its height (r3), stretched about the top to the length (r4).
        std::array<std::function<double(double)>, 2> earMaps;
        for (std::size_t side = 0; side < 2; ++side) {
            const glm::dvec2 top = P.a[2 * side], bottom = P.a[2 * side + 1];
            const double above = top.y >= yF ? 1.0 : -1.0;
            const double topTarget = yF + above * target.r[3] * W;
            const double stretch = (target.r[4] * W) / std::max(top.y - bottom.y, 1e-6);
            const auto map = [=](double y) { return topTarget + stretch * (y - top.y); };
            earMaps[side] = map;
            // The ear's outermost vertex between its notches tells where it is in depth and how far it reaches.
            const double sign = side == 0 ? -1.0 : 1.0;
            glm::dvec3 outer(0.0);
            for (const auto& p : out.mesh.positions)
                if (p.y <= top.y && p.y >= bottom.y && sign * p.x > sign * outer.x) outer = p;
            // The notches are where the ear meets the head's outline: the region reaches in past them, so that
            // they move with the ear (the side of the head there slides vertically, which leaves its shape).
            const double attach = std::min(std::abs(top.x), std::abs(bottom.x)) - 0.15 * eyeDistance;
            const double maxMove = std::max(std::abs(map(top.y) - top.y), std::abs(map(bottom.y) - bottom.y));
            const double yMargin = std::max(0.15 * eyeDistance, 1.6 * maxMove);
            bones.push_back([=](const glm::dvec3& p) -> glm::dvec2 {
                if (sign * p.x <= 0.0) return {0.0, 0.0};
                const double w = fadeIn(std::abs(p.x), attach, 0.1 * eyeDistance) *
                                 band(p.y, bottom.y, top.y, yMargin) *
                                 band(p.z, outer.z - 0.3 * eyeDistance, outer.z + 0.2 * eyeDistance, 0.15 * eyeDistance);
                return {0.0, w * (map(p.y) - p.y)};
            });
        }

        std::vector<glm::dvec2> moves(out.mesh.positions.size(), glm::dvec2(0.0));
        for (std::size_t v = 0; v < out.mesh.positions.size(); ++v)
            for (const Bone& bone : bones) moves[v] += bone(out.mesh.positions[v]);
        for (std::size_t v = 0; v < out.mesh.positions.size(); ++v) {
            out.mesh.positions[v].x += moves[v].x;
            out.mesh.positions[v].y += moves[v].y;
        }
        out.earHole.y = 0.5 * (earMaps[0](out.earHole.y) + earMaps[1](out.earHole.y));
    }
    out.achieved = measureHead(out.mesh, base, out.earHole, settings.pxPerMm).proportions;
    out.texture = paintCharacterTexture(base, settings.textureSize, look);
    return out;
}

cv::Mat paintCharacterTexture(const BaseHead& base, int textureSize, const CharacterLook& look) {
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

    cv::Mat texture = paintTexels(texels, [&](const glm::dvec3& p, const cv::Vec3f& nf) {
        const glm::dvec2 q(p.x, p.y);
        cv::Vec3b c = skin;
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
    });
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
