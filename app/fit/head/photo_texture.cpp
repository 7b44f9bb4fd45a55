// Photo texturing: per-photo visibility (z-buffers), one photo per texel, colour matching, a multi-band seam, fill.
//
// Why one photo per texel and not a weighted mean of both: the two photos are registered to the surface through
// different coordinates (the front through x and y, the side through z and y), and off the profile line the fitted
// z is the base head's guess. Where both were averaged, the side photo's lips and brows landed a few millimetres
// from the front photo's and showed as a second, ghosted copy. A hard choice keeps every feature from one photo;
// the multi-band blend then hides the seam: low frequencies (exposure, white balance, shading) cross it over a wide
// band, fine detail switches at it.
#include "fit/head/photo_texture.h"

#include "common/error.h"
#include "common/smoothstep.h"
#include "fit/head/surface_texels.h"
#include "fit/head/view_depth.h"

#include <opencv2/imgproc.hpp>
#include <opencv2/stitching/detail/blenders.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace avatarbooth {

void pullPushFill(cv::Mat& colour, cv::Mat& weight) {
    // Pull: average known texels (premultiplied by their weight) into ever coarser levels. Push: give each unknown
    // texel of a finer level the (bilinearly upsampled) colour of the level below it, so holes take a smooth mean
    // of what surrounds them.
    if (colour.type() != CV_32FC3 || weight.type() != CV_32F || colour.size() != weight.size())
        throw BoothError(ErrorKind::Internal, "", "pull-push fill: needs CV_32FC3 colours and CV_32F weights of one size");
    if (colour.empty()) return;
    std::vector<cv::Mat> pyramid(1);
    pyramid[0].create(colour.size(), CV_32FC4);
    for (int y = 0; y < colour.rows; ++y) {
        const cv::Vec3f* c = colour.ptr<cv::Vec3f>(y);
        const float* w = weight.ptr<float>(y);
        cv::Vec4f* p = pyramid[0].ptr<cv::Vec4f>(y);
        for (int x = 0; x < colour.cols; ++x) {
            const float a = std::clamp(w[x], 0.0f, 1.0f);
            p[x] = cv::Vec4f(c[x][0] * a, c[x][1] * a, c[x][2] * a, a);
        }
    }
    while (pyramid.back().rows > 1 || pyramid.back().cols > 1) {
        const cv::Mat& fine = pyramid.back();
        cv::Mat coarse;
        cv::resize(fine, coarse, cv::Size((fine.cols + 1) / 2, (fine.rows + 1) / 2), 0, 0, cv::INTER_AREA);
        pyramid.push_back(coarse);
    }
    // Push, coarsest first. Above the finest level a texel with any known content counts as known (its normalised
    // colour), which keeps the fill from washing out towards the holes' middle.
    cv::Mat filled;  // CV_32FC3, the level below, complete
    for (int level = static_cast<int>(pyramid.size()) - 1; level >= 0; --level) {
        const cv::Mat& p = pyramid[static_cast<std::size_t>(level)];
        cv::Mat up;
        if (!filled.empty()) cv::resize(filled, up, p.size(), 0, 0, cv::INTER_LINEAR);
        cv::Mat out(p.size(), CV_32FC3);
        for (int y = 0; y < p.rows; ++y) {
            const cv::Vec4f* q = p.ptr<cv::Vec4f>(y);
            const cv::Vec3f* u = up.empty() ? nullptr : up.ptr<cv::Vec3f>(y);
            cv::Vec3f* o = out.ptr<cv::Vec3f>(y);
            const cv::Vec3f* original = level == 0 ? colour.ptr<cv::Vec3f>(y) : nullptr;
            for (int x = 0; x < p.cols; ++x) {
                const float a = q[x][3];
                const cv::Vec3f below = u ? u[x] : cv::Vec3f(0, 0, 0);
                if (level == 0) {
                    o[x] = original[x] * a + below * (1.0f - a);
                } else if (a > 1e-6f) {
                    o[x] = cv::Vec3f(q[x][0], q[x][1], q[x][2]) / a;
                } else {
                    o[x] = below;
                }
            }
        }
        filled = out;
    }
    colour = filled;
    weight.setTo(1.0f);
}

void bleedIntoClearTexels(cv::Mat& bgra, int opaqueFrom) {
    if (bgra.type() != CV_8UC4)
        throw BoothError(ErrorKind::Internal, "", "bleedIntoClearTexels: needs a CV_8UC4 texture");
    if (bgra.empty()) return;
    cv::Mat bgr, alpha, own, fill, weight;
    cv::cvtColor(bgra, bgr, cv::COLOR_BGRA2BGR);
    cv::extractChannel(bgra, alpha, 3);
    bgr.convertTo(own, CV_32FC3);
    // The opaque texels alone are the fill's source: a partly clear one would lend its dark colour to all the clear
    // texels round it (pullPushFill takes any content of a coarse level for known).
    const int from = std::clamp(opaqueFrom, 1, 255);
    cv::Mat opaque = alpha >= from;
    opaque.convertTo(weight, CV_32F, 1.0 / 255.0);
    fill = own.clone();
    pullPushFill(fill, weight);
    // Partly clear texels over half the opacity keep some of their own colour, in proportion.
    const double half = from / 2.0;
    for (int y = 0; y < bgra.rows; ++y) {
        const auto* a = alpha.ptr<std::uint8_t>(y);
        const auto* o = own.ptr<cv::Vec3f>(y);
        const auto* f = fill.ptr<cv::Vec3f>(y);
        auto* out = bgra.ptr<cv::Vec4b>(y);
        for (int x = 0; x < bgra.cols; ++x) {
            const auto keep = static_cast<float>(std::clamp((a[x] - half) / std::max(from - half, 1.0), 0.0, 1.0));
            const cv::Vec3f c = keep * o[x] + (1.0f - keep) * f[x];
            for (int k = 0; k < 3; ++k) out[x][k] = cv::saturate_cast<std::uint8_t>(c[k]);
        }
    }
}

namespace {

// Rings of neighbours the normals that choose between the photos are averaged over (the face's grid spacing is
// 2-3 mm, so about a centimetre).
constexpr int kDecisionRings = 4;
// Seen more obliquely than this (about 80 degrees), a photo's pixel smears over many texels: not used.
constexpr float kMinCosine = 0.17f;

// What the texture step needs of one vertex, in both views. Everything a texel needs is interpolated from its
// triangle's three vertices (the views are orthographic, so positions and depths are exactly linear; the cosines
// and tolerances nearly so), which keeps square roots and divisions out of the million-texel loops.
struct VertexViews {
    float fu, fv, su, sv;  // front and side photo pixels (pixel centres at integers)
    float z, x;            // depth towards the front camera (z) and towards the +x side camera (x)
    float cosFront;        // normal . (0, 0, 1)
    float cosSide;         // normal . (1, 0, 0): its sign says which side camera faces the surface
    float tolFront, tolSide;  // depth tolerances of the visibility tests, millimetres
    float frontBetter;     // > 0 where the front photo is to be preferred (from the smoothed normals)
};

// A quantity that is affine in the texel position within one triangle: value = c + gx x + gy y for texel (x, y).
struct Affine {
    float c = 0, gx = 0, gy = 0;
    float at(float x, float y) const { return c + gx * x + gy * y; }
};
struct TexelToPhoto {
    Affine fu, fv, su, sv;
};

// Triangle `t`'s corners in texel units (x right, y down), and whether it covers any area there.
bool texelCorners(const Mesh& mesh, const glm::uvec3& t, cv::Size size, std::array<glm::dvec2, 3>& p) {
    const std::uint32_t idx[3] = {t.x, t.y, t.z};
    for (int k = 0; k < 3; ++k) p[k] = glm::dvec2(mesh.uvs[idx[k]].x * size.width, mesh.uvs[idx[k]].y * size.height);
    const glm::dvec2 e1 = p[1] - p[0], e2 = p[2] - p[0];
    return std::abs(e1.x * e2.y - e2.x * e1.y) >= 1e-12;  // degenerate in UV: no texel maps to it
}

// The quantity that is a0, a1, a2 at the corners p of a triangle (texel units), as an affine function of the texel
// (x, y) whose centre is at (x + 0.5, y + 0.5). The triangle must not be degenerate (texelCorners).
Affine affineOver(const std::array<glm::dvec2, 3>& p, double a0, double a1, double a2) {
    const glm::dvec2 e1 = p[1] - p[0], e2 = p[2] - p[0];
    const double det = e1.x * e2.y - e2.x * e1.y;
    const double d1 = a1 - a0, d2 = a2 - a0;
    const double gx = (d1 * e2.y - d2 * e1.y) / det, gy = (d2 * e1.x - d1 * e2.x) / det;
    // Fold the texel centre's half and the first corner into the constant.
    return Affine{static_cast<float>(a0 + gx * (0.5 - p[0].x) + gy * (0.5 - p[0].y)), static_cast<float>(gx), static_cast<float>(gy)};
}

// Vertex normals averaged over a few rings of neighbours. They decide which photo a texel takes: the fitted mesh has
// creases (where the base head's parts meet, the nose's and lips' rims) whose normals turn sideways over a few
// millimetres, and with the texel's own normal those thin strips went to the side photo and carried its lips and
// nose edges into the face as slivers.
std::vector<glm::dvec3> smoothedNormals(const Mesh& mesh, std::vector<glm::dvec3> normals, int rings) {
    std::vector<glm::dvec3> sum(normals.size());
    for (int ring = 0; ring < rings; ++ring) {
        sum = normals;
        for (const auto& t : mesh.triangles) {
            const std::uint32_t v[3] = {t.x, t.y, t.z};
            for (int k = 0; k < 3; ++k) sum[v[k]] += normals[v[(k + 1) % 3]] + normals[v[(k + 2) % 3]];
        }
        for (std::size_t i = 0; i < normals.size(); ++i) {
            const double length = glm::length(sum[i]);
            normals[i] = length > 1e-12 ? sum[i] / length : normals[i];
        }
    }
    return normals;
}

// Bilinear sample of an 8-bit BGR photo at (u, v), pixel centres at integers. The caller has checked that the
// nearest pixel is inside the photo, so u, v >= -0.5 (truncation is then a floor, after the clamp to 0). Fixed-point
// weights (1/128): this runs a million times per texture, and byte-to-float conversions were its main cost.
inline cv::Vec3f bilinear(const cv::Mat& photo, float u, float v) {
    const int x0 = std::min(static_cast<int>(std::max(u, 0.0f)), photo.cols - 2);
    const int y0 = std::min(static_cast<int>(std::max(v, 0.0f)), photo.rows - 2);
    const int wx = static_cast<int>(std::clamp(u - static_cast<float>(x0), 0.0f, 1.0f) * 128.0f + 0.5f);
    const int wy = static_cast<int>(std::clamp(v - static_cast<float>(y0), 0.0f, 1.0f) * 128.0f + 0.5f);
    const unsigned char* a = photo.ptr<unsigned char>(y0) + 3 * x0;
    const unsigned char* b = a + photo.step[0];
    cv::Vec3f out;
    for (int c = 0; c < 3; ++c) {
        const int top = a[c] * (128 - wx) + a[c + 3] * wx;
        const int bottom = b[c] * (128 - wx) + b[c + 3] * wx;
        out[c] = static_cast<float>(top * (128 - wy) + bottom * wy) * (1.0f / 16384.0f);
    }
    return out;
}

// Where full-resolution texel `full` reads an image `factor` times smaller (cells' centres at (i + 0.5) * factor):
// the two cells along one axis and the second's weight.
struct UpsampleTap {
    int i0, i1;
    float f;
};
UpsampleTap upsampleTap(int full, int smallLength, int factor) {
    const float h = (static_cast<float>(full) + 0.5f) / static_cast<float>(factor) - 0.5f;
    const int i0 = std::clamp(static_cast<int>(std::floor(h)), 0, smallLength - 1);
    return {i0, std::min(i0 + 1, smallLength - 1), std::clamp(h - static_cast<float>(i0), 0.0f, 1.0f)};
}

// Bilinear upsampling by two of a CV_32FC3 image, one full-resolution row at a time (full-resolution texel centre
// x + 0.5 is at half-resolution x / 2 - 0.25): the columns' taps are computed once.
class HalfToFull {
public:
    HalfToFull(cv::Size half, int fullWidth) : half_(half), taps_(static_cast<std::size_t>(fullWidth)) {
        for (int x = 0; x < fullWidth; ++x) taps_[static_cast<std::size_t>(x)] = upsampleTap(x, half.width, 2);
    }
    // Row y of the upsampled image, as two half-resolution rows and the weight of the second.
    void row(const cv::Mat& image, int y, const cv::Vec3f*& r0, const cv::Vec3f*& r1, float& fy) const {
        const UpsampleTap t = upsampleTap(y, half_.height, 2);
        r0 = image.ptr<cv::Vec3f>(t.i0);
        r1 = image.ptr<cv::Vec3f>(t.i1);
        fy = t.f;
    }
    cv::Vec3f at(const cv::Vec3f* r0, const cv::Vec3f* r1, float fy, int x) const {
        const UpsampleTap& t = taps_[static_cast<std::size_t>(x)];
        const cv::Vec3f top = r0[t.i0] + (r0[t.i1] - r0[t.i0]) * t.f;
        const cv::Vec3f bottom = r1[t.i0] + (r1[t.i1] - r1[t.i0]) * t.f;
        return top + (bottom - top) * fy;
    }

private:
    cv::Size half_;
    std::vector<UpsampleTap> taps_;
};

// A silhouette shrunk by two pixels: photo pixels at the outline are part background, and a texel that samples
// them takes a dark fringe (the profile's edge showed as dark lines across the lips and brows).
cv::Mat interiorOf(const cv::Mat& mask) {
    cv::Mat inner;
    cv::erode(mask, inner, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 5)));
    return inner;
}

// Where the side photo is read for a point of the head (pixels), shifted from the profile's projection:
// - Turned short of the profile (or past it), the side photo shows the side of the head further back (or forward)
//   than a profile would; the outline, which the fit matched, stays. The side photo's eye measures it
//   (HeadFit::eyeLeftMm): the photo is read shifted by that much, sideways only (a turn about the vertical moves
//   nothing up or down), from the eye's distance off the midline outwards, and by a share growing from none on the
//   midline towards it; up or down only round the eye (eyeReachMm, eyeFadeMm).
// - Round the ears by what the ears' placement left between the head's ear and the photo's (in full within
//   earReachMm of the ear's middle, fading out over earFadeMm or twice the shift if more, so that the reading cannot
//   fold); both ears, as the photo stands in for the far side too.
cv::Point2d sidePhotoPoint(const HeadFit& fit, const PhotoTextureOptions& options, const glm::dvec3& p) {
    // The feature on p's side of the head (the photo stands in for both).
    const auto onSideOf = [&](const glm::dvec3& m) { return (p.x < 0.0) == (m.x < 0.0) ? m : glm::dvec3(-m.x, m.y, m.z); };
    double ear = 0.0;  // the ear's share
    if (fit.earsPlaced) {
        const double fade = std::max(options.earFadeMm, 2.0 * glm::length(fit.earLeftMm));
        ear = 1.0 - smoothstep(std::clamp((glm::distance(p, onSideOf(fit.earMiddleMm)) - options.earReachMm) / fade, 0.0, 1.0));
    }
    glm::dvec2 shift = ear * fit.earLeftMm;
    if (fit.sideEyeFound) {
        const double offMidline = std::max(std::abs(fit.eyeMiddleMm.x), 1.0);
        shift.x += (1.0 - ear) * smoothstep(std::min(std::abs(p.x) / offMidline, 1.0)) * fit.eyeLeftMm.x;
        const double fade = std::max(options.eyeFadeMm, 2.0 * std::abs(fit.eyeLeftMm.y));
        shift.y += (1.0 - smoothstep(std::clamp((glm::distance(p, onSideOf(fit.eyeMiddleMm)) - options.eyeReachMm) / fade, 0.0, 1.0))) *
                   fit.eyeLeftMm.y;
    }
    return fit.side.toPixel(glm::dvec2(p.z, p.y) + shift);
}

// Whether a photo's pixel at (u, v) is skin by the not-skin mask (no mask: every pixel of the person counts).
bool isSkin(const cv::Mat& notSkin, float u, float v) {
    if (notSkin.empty()) return true;
    const int x = std::clamp(static_cast<int>(std::lround(u)), 0, notSkin.cols - 1);
    const int y = std::clamp(static_cast<int>(std::lround(v)), 0, notSkin.rows - 1);
    return notSkin.at<unsigned char>(y, x) == 0;
}

// Half-resolution texels of skin both photos must see well for the exposure match (a face has several thousand).
constexpr long kMinMatchTexels = 50;

// The per-texel decision, shared by the half- and the full-resolution pass.
struct TexelView {
    bool seenFront = false, seenSide = false, frontChosen = false, facesFront = false;
    float fu = 0, fv = 0, su = 0, sv = 0;
    float cosFront = 0, cosSide = 0;
};

class TexelClassifier {
public:
    TexelClassifier(const Mesh& mesh, const std::vector<VertexViews>& views, const std::array<cv::Mat, 3>& depth,
                    const cv::Mat& frontInner, const cv::Mat& sideInner)
        : mesh_(mesh), views_(views), depth_(depth), frontInner_(frontInner), sideInner_(sideInner) {}

    TexelView operator()(int triangle, float b0, float b1) const {
        const glm::uvec3& t = mesh_.triangles[static_cast<std::size_t>(triangle)];
        const float b2 = 1.0f - b0 - b1;
        const VertexViews& A = views_[t.x];
        const VertexViews& B = views_[t.y];
        const VertexViews& C = views_[t.z];
        const auto mix = [&](float VertexViews::*m) { return b0 * A.*m + b1 * B.*m + b2 * C.*m; };
        TexelView v;
        v.fu = mix(&VertexViews::fu);
        v.fv = mix(&VertexViews::fv);
        v.su = mix(&VertexViews::su);
        v.sv = mix(&VertexViews::sv);
        v.cosFront = mix(&VertexViews::cosFront);
        const float cosSide = mix(&VertexViews::cosSide);
        v.cosSide = std::abs(cosSide);
        v.facesFront = v.cosFront > v.cosSide;
        if (v.cosFront > kMinCosine)
            v.seenFront = visible(depth_[0], frontInner_, v.fu, v.fv, mix(&VertexViews::z), mix(&VertexViews::tolFront));
        // The side camera on the side the surface faces: -x is the side photo's own view, +x its mirror image.
        if (v.cosSide > kMinCosine) {
            const float x = mix(&VertexViews::x);
            v.seenSide = cosSide < 0.0f ? visible(depth_[1], sideInner_, v.su, v.sv, -x, mix(&VertexViews::tolSide))
                                        : visible(depth_[2], sideInner_, v.su, v.sv, x, mix(&VertexViews::tolSide));
        }
        v.frontChosen = v.seenFront && (!v.seenSide || mix(&VertexViews::frontBetter) >= 0.0f);
        return v;
    }

private:
    // Inside the silhouette, and no surface nearer the camera than this one at its pixel (the z-buffer is read at the
    // nearest pixel centre; the tolerance covers the surface's slope over that distance).
    static bool visible(const cv::Mat& z, const cv::Mat& mask, float u, float v, float depth, float tolerance) {
        if (!(u >= -0.5f && v >= -0.5f)) return false;  // (also rejects NaN)
        const int x = static_cast<int>(u + 0.5f), y = static_cast<int>(v + 0.5f);
        if (x >= z.cols || y >= z.rows) return false;
        return mask.ptr<unsigned char>(y)[x] != 0 && depth >= z.ptr<float>(y)[x] - tolerance;
    }

    const Mesh& mesh_;
    const std::vector<VertexViews>& views_;
    const std::array<cv::Mat, 3>& depth_;
    const cv::Mat& frontInner_;
    const cv::Mat& sideInner_;
};

inline cv::Vec3b toBgr(const cv::Vec3f& c) {
    return {cv::saturate_cast<unsigned char>(c[0]), cv::saturate_cast<unsigned char>(c[1]), cv::saturate_cast<unsigned char>(c[2])};
}

int checkedTextureSize(const PhotoTextureOptions& options) {
    if (options.size < 16) throw BoothError(ErrorKind::Internal, "", "texture: the size must be at least 16 texels");
    return options.size;
}

const Mesh& withUvs(const Mesh& mesh) {
    if (mesh.uvs.size() != mesh.positions.size())
        throw BoothError(ErrorKind::Internal, "", "texture: the mesh has no texture coordinates");
    return mesh;
}

}  // namespace

TextureTables::TextureTables(const Mesh& base, const PhotoTextureOptions& options, const cv::Mat& skin,
                             const std::vector<std::uint32_t>& frontFeatures)
    : vertices_(withUvs(base).uvs.size()), triangles_(base.triangles.size()),
      full_(mapTexels(base, cv::Size(checkedTextureSize(options), options.size))),
      half_(mapTexels(base, cv::Size((options.size + 1) / 2, (options.size + 1) / 2))) {
    if (!frontFeatures.empty()) {
        frontPreference_.resize(base.positions.size());
        for (std::size_t v = 0; v < base.positions.size(); ++v) {
            double nearest = std::numeric_limits<double>::infinity();
            for (const std::uint32_t f : frontFeatures) {
                if (f >= base.positions.size())
                    throw BoothError(ErrorKind::Internal, "", "texture: a front feature vertex is not on the base head");
                nearest = std::min(nearest, glm::distance(base.positions[v], base.positions[f]));
            }
            const double t = std::clamp((nearest - options.featureReachMm) / std::max(options.featureFadeMm, 1e-9), 0.0, 1.0);
            frontPreference_[v] = static_cast<float>(options.featureFrontPreference +
                                                     (options.frontPreference - options.featureFrontPreference) * t);
        }
    }
    if (skin.empty()) return;
    // The skin layer's detail: its difference from its own blur (finer than about 1/40 of the texture: a crease, an
    // ear's fold), made once here because the wide blur is the costly part.
    cv::Mat layer;
    cv::resize(skin, layer, cv::Size(options.size, options.size), 0, 0, cv::INTER_AREA);
    layer.convertTo(layer, CV_32FC3);
    cv::Mat smooth;
    cv::GaussianBlur(layer, smooth, cv::Size(), options.size / 80.0);
    // Held as whole levels in 8 bits (3 MB at 1024 texels instead of 12.6 MB of floats): the detail is added to
    // 8-bit texels, and a fold's shading lies well within +-127 levels of its surroundings (beyond, it saturates).
    cv::subtract(layer, smooth, skinDetail_, cv::noArray(), CV_8S);
}

PhotoTexture textureFromPhotos(const Mesh& fitted, const HeadFit& fit, const cv::Mat& front, const cv::Mat& frontMask,
                               const cv::Mat& side, const cv::Mat& sideMask, const PhotoTextureOptions& options,
                               const ColourMatchMasks& notSkin) {
    return textureFromPhotos(fitted, fit, front, frontMask, side, sideMask, options, TextureTables(fitted, options), notSkin);
}

PhotoTexture textureFromPhotos(const Mesh& fitted, const HeadFit& fit, const cv::Mat& front, const cv::Mat& frontMask,
                               const cv::Mat& side, const cv::Mat& sideMask, const PhotoTextureOptions& options,
                               const TextureTables& tables, const ColourMatchMasks& notSkin) {
    if (front.empty() || side.empty() || front.type() != CV_8UC3 || side.type() != CV_8UC3 || front.cols < 2 ||
        front.rows < 2 || side.cols < 2 || side.rows < 2)
        throw BoothError(ErrorKind::Internal, "", "texture: the photos must be 8-bit BGR");
    if (frontMask.size() != front.size() || sideMask.size() != side.size() || frontMask.type() != CV_8U || sideMask.type() != CV_8U)
        throw BoothError(ErrorKind::Internal, "", "texture: each silhouette must be an 8-bit mask of its photo's size");
    for (const auto& [mask, photo] : {std::pair{&notSkin.frontNotSkin, &front}, std::pair{&notSkin.sideNotSkin, &side}})
        if (!mask->empty() && (mask->size() != photo->size() || mask->type() != CV_8U))
            throw BoothError(ErrorKind::Internal, "", "texture: a not-skin mask must be an 8-bit mask of its photo's size");
    checkedTextureSize(options);
    withUvs(fitted);
    if (tables.size() != options.size || !tables.fits(fitted))
        throw BoothError(ErrorKind::Internal, "", "texture: the texel tables were made for another mesh or size");
    const cv::Size size(options.size, options.size);
    const cv::Size half((size.width + 1) / 2, (size.height + 1) / 2);
    const TexelMap& map = tables.full();
    const TexelMap& halfMap = tables.half();

    // --- Each vertex in both views, and a z-buffer per camera: front (+z), the side photo's own side (-x), and the
    // other side (+x), which the side photo stands in for, mirrored. Orthographic views make the depth linear.
    const float strictness = static_cast<float>(options.angleStrictness);
    const auto weightOf = [strictness](double c) { return std::pow(std::max(c, 0.0), static_cast<double>(strictness)); };
    const double baseTolerance = options.depthToleranceMm;
    // A visible point's depth differs from the z-buffer at the nearest pixel centre by up to its slope times that
    // distance (under a pixel): allow 1.5 pixels of slope, capped where the photo sees the surface edge-on.
    const auto tolerance = [baseTolerance](double cosine, double mmPerPixel) {
        const double c = std::clamp(std::abs(cosine), 1e-3, 1.0);
        return static_cast<float>(baseTolerance + 1.5 * mmPerPixel * std::min(std::sqrt(1.0 - c * c) / c, 4.0));
    };
    const std::vector<glm::dvec3> normals = fitted.vertexNormals();
    const std::vector<glm::dvec3> smooth = smoothedNormals(fitted, normals, kDecisionRings);
    std::vector<VertexViews> views(fitted.positions.size());
    std::array<std::vector<ViewVertex>, 3> depthVertices;  // front, from -x, from +x
    for (auto& d : depthVertices) d.resize(fitted.positions.size());
    for (std::size_t i = 0; i < fitted.positions.size(); ++i) {
        const glm::dvec3& p = fitted.positions[i];
        const cv::Point2d f = fit.front.toPixel({p.x, p.y});
        const cv::Point2d s = sidePhotoPoint(fit, options, p);
        const glm::dvec3& n = normals[i];
        const glm::dvec3& m = smooth[i];
        VertexViews& v = views[i];
        v.fu = static_cast<float>(f.x);
        v.fv = static_cast<float>(f.y);
        v.su = static_cast<float>(s.x);
        v.sv = static_cast<float>(s.y);
        v.z = static_cast<float>(p.z);
        v.x = static_cast<float>(p.x);
        v.cosFront = static_cast<float>(n.z);
        v.cosSide = static_cast<float>(n.x);
        v.tolFront = tolerance(n.z, fit.front.mmPerPixel);
        v.tolSide = tolerance(n.x, fit.side.mmPerPixel);
        const double preference = tables.frontPreference().empty() ? options.frontPreference : tables.frontPreference()[i];
        v.frontBetter = static_cast<float>(preference * weightOf(m.z) - weightOf(std::abs(m.x)));
        depthVertices[0][i] = {v.fu, v.fv, v.z};
        depthVertices[1][i] = {v.su, v.sv, -v.x};
        depthVertices[2][i] = {v.su, v.sv, v.x};
    }
    // Each camera's z-buffer needs only the triangles facing it: on a closed surface the nearest one along any ray
    // does (this halves the rasterising).
    std::array<std::vector<glm::uvec3>, 3> facing;
    for (const auto& t : fitted.triangles) {
        const glm::dvec3& a = fitted.positions[t.x];
        const glm::dvec3 n = glm::cross(fitted.positions[t.y] - a, fitted.positions[t.z] - a);
        if (n.z > 0.0) facing[0].push_back(t);
        if (n.x < 0.0) facing[1].push_back(t);
        if (n.x > 0.0) facing[2].push_back(t);
    }
    // Where the front and the side photo pixels of a texel are, as an affine function of the texel's position per
    // triangle (exact: UVs, barycentrics and orthographic projections are all affine): the full-resolution pass
    // then reads one triangle's coefficients per texel instead of three vertices and the barycentric map.
    std::vector<TexelToPhoto> toPhoto(fitted.triangles.size());
    for (std::size_t ti = 0; ti < fitted.triangles.size(); ++ti) {
        const glm::uvec3& t = fitted.triangles[ti];
        std::array<glm::dvec2, 3> p;
        if (!texelCorners(fitted, t, size, p)) continue;
        const auto affine = [&](float VertexViews::*m) { return affineOver(p, views[t.x].*m, views[t.y].*m, views[t.z].*m); };
        toPhoto[ti] = {affine(&VertexViews::fu), affine(&VertexViews::fv), affine(&VertexViews::su), affine(&VertexViews::sv)};
    }
    std::array<cv::Mat, 3> depth;
    std::array<cv::Mat, 2> inner;
    cv::parallel_for_(cv::Range(0, 5), [&](const cv::Range& r) {
        for (int k = r.start; k < r.end; ++k) {
            const auto i = static_cast<std::size_t>(k);
            if (k < 3) depth[i] = rasteriseNearestDepth(depthVertices[i], facing[i], k == 0 ? front.size() : side.size());
            else inner[i - 3] = interiorOf(k == 3 ? frontMask : sideMask);
        }
    });
    const TexelClassifier classify(fitted, views, depth, inner[0], inner[1]);

    // --- Half resolution: both photos' colours wherever they see the surface (for the blend's coarse bands), the
    // choice of photo as the blend's masks, and the exposure comparison. Rows in stripes over the two cores; sums
    // per stripe, added up afterwards.
    cv::Mat frontHalf(half, CV_32FC3, cv::Scalar::all(0)), sideHalf(half, CV_32FC3, cv::Scalar::all(0));
    cv::Mat frontSeen(half, CV_32F, cv::Scalar(0)), sideSeen(half, CV_32F, cv::Scalar(0));
    cv::Mat frontLabel(half, CV_8U, cv::Scalar(0));  // 255 where the blend takes the front photo's bands
    // The exposure match's comparisons summed over cells of kShrink x kShrink texels (its local gain varies slowly):
    // both photos' colours and the count per cell. Stripes of whole cell rows, so that no two threads share a cell.
    constexpr int kShrink = 4;
    const cv::Size coarse((half.width + kShrink - 1) / kShrink, (half.height + kShrink - 1) / kShrink);
    cv::Mat frontNear(coarse, CV_32FC3, cv::Scalar::all(0)), sideNear(coarse, CV_32FC3, cv::Scalar::all(0));
    cv::Mat weightNear(coarse, CV_32F, cv::Scalar(0));
    cv::Mat halfSource(half, CV_8U, cv::Scalar(PhotoTexture::Filled));  // the photo each texel takes
    constexpr int kStripes = 16;
    std::array<cv::Vec3d, kStripes> frontSum{}, sideSum{};
    std::array<long, kStripes> overlapCount{};
    cv::parallel_for_(cv::Range(0, kStripes), [&](const cv::Range& stripes) {
        for (int stripe = stripes.start; stripe < stripes.end; ++stripe) {
            cv::Vec3d frontAcc(0, 0, 0), sideAcc(0, 0, 0);  // locals: neighbouring array entries share a cache line
            long overlapAcc = 0;
            const auto stripeStart = [&](int k) { return std::min(half.height, coarse.height * k / kStripes * kShrink); };
            for (int y = stripeStart(stripe); y < stripeStart(stripe + 1); ++y) {
                const int* tri = halfMap.triangle.ptr<int>(y);
                cv::Vec3f* frontCell = frontNear.ptr<cv::Vec3f>(y / kShrink);
                cv::Vec3f* sideCell = sideNear.ptr<cv::Vec3f>(y / kShrink);
                float* weightCell = weightNear.ptr<float>(y / kShrink);
                cv::Vec3f* fc = frontHalf.ptr<cv::Vec3f>(y);
                cv::Vec3f* sc = sideHalf.ptr<cv::Vec3f>(y);
                float* fw = frontSeen.ptr<float>(y);
                float* sw = sideSeen.ptr<float>(y);
                unsigned char* label = frontLabel.ptr<unsigned char>(y);
                unsigned char* src = halfSource.ptr<unsigned char>(y);
                for (int x = 0; x < half.width; ++x) {
                    if (tri[x] < 0) continue;
                    const cv::Vec2d bary = halfMap.barycentric(tri[x], x, y);
                    const TexelView v = classify(tri[x], static_cast<float>(bary[0]), static_cast<float>(bary[1]));
                    if (v.seenFront) {
                        fc[x] = bilinear(front, v.fu, v.fv);
                        fw[x] = 1.0f;
                    }
                    if (v.seenSide) {
                        sc[x] = bilinear(side, v.su, v.sv);
                        sw[x] = 1.0f;
                    }
                    // Unseen texels are filled; the fill there is blended from the photo the surface faces most.
                    if (v.frontChosen || (!v.seenFront && !v.seenSide && v.facesFront)) label[x] = 255;
                    src[x] = v.frontChosen ? PhotoTexture::Front : (v.seenSide ? PhotoTexture::Side : PhotoTexture::Filled);
                    if (v.seenFront && v.seenSide && v.cosFront > 0.4f && v.cosSide > 0.4f &&
                        isSkin(notSkin.frontNotSkin, v.fu, v.fv) && isSkin(notSkin.sideNotSkin, v.su, v.sv)) {
                        frontAcc += cv::Vec3d(fc[x][0], fc[x][1], fc[x][2]);
                        sideAcc += cv::Vec3d(sc[x][0], sc[x][1], sc[x][2]);
                        ++overlapAcc;
                        frontCell[x / kShrink] += fc[x];
                        sideCell[x / kShrink] += sc[x];
                        weightCell[x / kShrink] += 1.0f;
                    }
                }
            }
            const auto s = static_cast<std::size_t>(stripe);
            frontSum[s] = frontAcc;
            sideSum[s] = sideAcc;
            overlapCount[s] = overlapAcc;
        }
    }, kStripes);

    // --- The photos differ in exposure and white balance: match the side photo's colour to the front's where both
    // see the same skin well (per-channel gain). Skin against skin only: long hair falls over the front photo's
    // temples and cheeks and lies behind them in the side photo, and compared with the skin there it set the gain
    // by the hair (FRMDB 006's and 008's right profiles were darkened by 13-16 %; on their skin alone the photos
    // agree within 3 %).
    cv::Vec3d frontTotal(0, 0, 0), sideTotal(0, 0, 0);
    long overlap = 0;
    for (std::size_t s = 0; s < kStripes; ++s) {
        frontTotal += frontSum[s];
        sideTotal += sideSum[s];
        overlap += overlapCount[s];
    }
    cv::Vec3f gain(1, 1, 1);
    if (overlap >= kMinMatchTexels)
        for (int c = 0; c < 3; ++c)
            gain[c] = static_cast<float>(std::clamp(frontTotal[c] / std::max(sideTotal[c], 1.0), 0.6, 1.6));

    // --- The multi-band blend. Its finest band switches at the seam; every coarser band is blended across it by
    // OpenCV's MultiBandBlender, run at half resolution on the two photos' colours. At full resolution a texel then
    // keeps its own photo's detail and takes the blended low frequencies:
    //   out = own colour + up(blend - own photo at half resolution),
    // which is the photo's colour exactly wherever the blend is all that photo's. Each photo's image is filled in
    // beyond what it saw (pull-push: a smooth continuation), so that the blend's coarse bands, which reach far past
    // the seam, meet plausible colours and no edge. (Filling one photo's gaps with the other photo's colours instead
    // put a hard edge into both images where the two photos' grazing views meet, and no blend can smooth an edge
    // both of its inputs have.)
    // The difference is not the same everywhere: the two photos' lights fall differently on the forehead, the
    // cheeks and the jaw (FRMDB 005's side-photo cheek read pale, 008's a light band beside the seam). So near the
    // skin both photos see, the gain is local: the same ratio over the compared texels round each texel (Gaussian-
    // weighted, exposureSmoothing of the texture's side). Further off (the neck, the back of the head, the ears) it
    // eases into the one gain: continued there, the local gains made blocks of light and shade on 002's neck.
    cv::Mat gainMap(half, CV_32FC3, cv::Scalar(gain[0], gain[1], gain[2]));
    if (overlap >= kMinMatchTexels && options.exposureSmoothing > 0.0) {
        // A gain varies slowly: it is measured on the cells' sums, a quarter of the half-resolution texture's side
        // (the Gaussians at half resolution cost 35 ms of processor time, at a quarter of it under 2), and read
        // bilinearly. Each cell's sums become its means over its 16 texels (an area average, compared or not).
        const double sigma = options.exposureSmoothing * coarse.width;
        constexpr double kPerCell = 1.0 / (kShrink * kShrink);
        frontNear *= kPerCell;
        sideNear *= kPerCell;
        weightNear *= kPerCell;
        cv::GaussianBlur(frontNear, frontNear, cv::Size(), sigma);
        cv::GaussianBlur(sideNear, sideNear, cv::Size(), sigma);
        cv::GaussianBlur(weightNear, weightNear, cv::Size(), sigma);
        // Fully local where the comparisons round a texel weigh a quarter of what a texel amid them has.
        constexpr float kFullyLocal = 0.25f;
        cv::Mat local(coarse, CV_32FC3);
        for (int y = 0; y < coarse.height; ++y)
            for (int x = 0; x < coarse.width; ++x) {
                const auto share = static_cast<float>(smoothstep(weightNear.at<float>(y, x) / kFullyLocal));
                const cv::Vec3f f = frontNear.at<cv::Vec3f>(y, x), sd = sideNear.at<cv::Vec3f>(y, x);
                cv::Vec3f& g = local.at<cv::Vec3f>(y, x);
                for (int c = 0; c < 3; ++c) {
                    const float ratio = sd[c] > 1e-3f ? std::clamp(f[c] / sd[c], 0.6f, 1.6f) : gain[c];
                    g[c] = share * ratio + (1.0f - share) * gain[c];
                }
            }
        cv::resize(local, gainMap, half, 0, 0, cv::INTER_LINEAR);
    }
    cv::multiply(sideHalf, gainMap, sideHalf);
    const cv::Mat frontSeenHalf = frontSeen > 0.0f, sideSeenHalf = sideSeen > 0.0f;
    cv::parallel_for_(cv::Range(0, 2), [&](const cv::Range& r) {
        for (int k = r.start; k < r.end; ++k) pullPushFill(k == 0 ? frontHalf : sideHalf, k == 0 ? frontSeen : sideSeen);
    });
    cv::Mat blended;
    {
        cv::detail::MultiBandBlender blender(false, std::max(options.blendBands - 1, 1), CV_32F);
        blender.prepare(cv::Rect(cv::Point(0, 0), half));
        cv::Mat frontShort, sideShort, blendedShort, blendMask;
        // The blender's pyramids are 16-bit integers and each level rounds: at 8-bit scale that biased the result
        // by 1-3 levels even where both inputs were the same. Sixteen times the scale keeps 4 bits of fraction
        // (255 * 16 and its band differences stay well inside 16 bits).
        constexpr double kScale = 16.0;
        frontHalf.convertTo(frontShort, CV_16SC3, kScale);
        sideHalf.convertTo(sideShort, CV_16SC3, kScale);
        blender.feed(frontShort, frontLabel, cv::Point(0, 0));
        blender.feed(sideShort, 255 - frontLabel, cv::Point(0, 0));
        blender.blend(blendedShort, blendMask);
        blendedShort.convertTo(blended, CV_32FC3, 1.0 / kScale);
    }
    const cv::Mat frontCorrection = blended - frontHalf, sideCorrection = blended - sideHalf;
    // Where a texel's half-resolution neighbours all took the same photo, the full-resolution texels among them
    // take it too without testing visibility again (no occluder edge passes there); elsewhere each decides itself.
    cv::Mat allFront, allSide;
    cv::erode(halfSource == PhotoTexture::Front, allFront, cv::Mat(), cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
    cv::erode(halfSource == PhotoTexture::Side, allSide, cv::Mat(), cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));

    // --- Full resolution: each texel decides again (visibility at its own point) and takes its photo's colour plus
    // the blend's correction; texels no photo sees, and those no triangle covers (the UV borders, which mipmapping
    // reads), take the blended fill.
    PhotoTexture out;
    out.texture.create(size, CV_8UC3);
    out.source = cv::Mat(size, CV_8U, cv::Scalar(PhotoTexture::Filled));
    std::array<int, kStripes> coveredCount{}, seenCount{};
    const HalfToFull upsample(half, size.width);
    cv::parallel_for_(cv::Range(0, kStripes), [&](const cv::Range& stripes) {
        for (int stripe = stripes.start; stripe < stripes.end; ++stripe) {
            int coveredAcc = 0, seenAcc = 0;
            for (int y = size.height * stripe / kStripes; y < size.height * (stripe + 1) / kStripes; ++y) {
                const int* tri = map.triangle.ptr<int>(y);
                unsigned char* src = out.source.ptr<unsigned char>(y);
                cv::Vec3b* o = out.texture.ptr<cv::Vec3b>(y);
                const cv::Vec3f *f0, *f1, *s0, *s1, *b0, *b1;
                float fy = 0.0f;
                upsample.row(frontCorrection, y, f0, f1, fy);
                upsample.row(sideCorrection, y, s0, s1, fy);
                upsample.row(blended, y, b0, b1, fy);
                const unsigned char* uniformFront = allFront.ptr<unsigned char>(std::min(y / 2, half.height - 1));
                const unsigned char* uniformSide = allSide.ptr<unsigned char>(std::min(y / 2, half.height - 1));
                const unsigned char* frontSeenRow = frontSeenHalf.ptr<unsigned char>(std::min(y / 2, half.height - 1));
                const unsigned char* sideSeenRow = sideSeenHalf.ptr<unsigned char>(std::min(y / 2, half.height - 1));
                const cv::Vec3f* gainRow = gainMap.ptr<cv::Vec3f>(std::min(y / 2, half.height - 1));
                for (int x = 0; x < size.width; ++x) {
                    if (tri[x] >= 0) {
                        ++coveredAcc;
                        const int hx = std::min(x / 2, half.width - 1);
                        const float fx = static_cast<float>(x), fyRow = static_cast<float>(y);
                        const TexelToPhoto& a = toPhoto[static_cast<std::size_t>(tri[x])];
                        if (uniformFront[hx]) {
                            o[x] = toBgr(bilinear(front, a.fu.at(fx, fyRow), a.fv.at(fx, fyRow)) + upsample.at(f0, f1, fy, x));
                            src[x] = PhotoTexture::Front;
                            ++seenAcc;
                            continue;
                        }
                        if (uniformSide[hx]) {
                            const cv::Vec3f c = bilinear(side, a.su.at(fx, fyRow), a.sv.at(fx, fyRow));
                            const cv::Vec3f& gm = gainRow[hx];
                            o[x] = toBgr(cv::Vec3f(c[0] * gm[0], c[1] * gm[1], c[2] * gm[2]) + upsample.at(s0, s1, fy, x));
                            src[x] = PhotoTexture::Side;
                            ++seenAcc;
                            continue;
                        }
                        // A texel takes a photo only where the half-resolution pass saw that photo too: its
                        // correction subtracts that photo's half-resolution colour, which elsewhere is a stand-in
                        // (the other photo's, or the fill), and the difference would show as a step.
                        const cv::Vec2d bary = map.barycentric(tri[x], x, y);
                        const TexelView v = classify(tri[x], static_cast<float>(bary[0]), static_cast<float>(bary[1]));
                        const bool frontThere = v.seenFront && frontSeenRow[hx], sideThere = v.seenSide && sideSeenRow[hx];
                        if (frontThere && (v.frontChosen || !sideThere)) {
                            o[x] = toBgr(bilinear(front, v.fu, v.fv) + upsample.at(f0, f1, fy, x));
                            src[x] = PhotoTexture::Front;
                            ++seenAcc;
                            continue;
                        }
                        if (sideThere) {
                            const cv::Vec3f c = bilinear(side, v.su, v.sv);
                            const cv::Vec3f& gm = gainRow[hx];
                            o[x] = toBgr(cv::Vec3f(c[0] * gm[0], c[1] * gm[1], c[2] * gm[2]) + upsample.at(s0, s1, fy, x));
                            src[x] = PhotoTexture::Side;
                            ++seenAcc;
                            continue;
                        }
                    }
                    o[x] = toBgr(upsample.at(b0, b1, fy, x));
                }
            }
            coveredCount[static_cast<std::size_t>(stripe)] = coveredAcc;
            seenCount[static_cast<std::size_t>(stripe)] = seenAcc;
        }
    }, kStripes);
    int covered = 0, seen = 0;
    for (std::size_t s = 0; s < kStripes; ++s) {
        covered += coveredCount[s];
        seen += seenCount[s];
    }
    out.seenFraction = covered > 0 ? static_cast<double>(seen) / covered : 0.0;
    out.sideGain = gain;
    out.sideGainTexels = overlap >= kMinMatchTexels ? static_cast<int>(overlap) : 0;
    addBaseLayerDetail(out, tables.skinDetail());
    return out;
}

namespace {

// A texel as a repaint sees it: the point of the head and, when it took a photo (`seen`), which and where in it
// (`pixel`: interpolated over the triangle from its corners' pixels, as the texture read it).
struct PhotoTexel {
    glm::dvec3 head;
    bool seen = false, front = false;
    cv::Point2d pixel;
};

// Where a texel of a triangle lies on the head and in each photo, as affine functions of the texel's position.
struct TexelToHead {
    Affine x, y, z;
    TexelToPhoto photo;
};
// What such a texel is to a repaint: a source of the skin's colour, or repainted by `repaint` (0..1), or neither.
struct TexelRole {
    bool skin = false;
    float repaint = 0.0f;
};

// The part of the texture a repaint looks at: the triangles that may matter to it and the texels' box round them
// (the fill and the feather reach 8 texels past it), so that a repaint of the neck does not visit the whole head.
struct RepaintArea {
    std::vector<unsigned char> triangles;  // per triangle of the mesh, 1 where it matters
    cv::Rect box;                          // texels
};

// The triangles of which any corner `near(position)` says matters, and their box in the texture.
template <typename Near>
RepaintArea repaintArea(const Mesh& fitted, cv::Size size, const Near& near) {
    RepaintArea area;
    area.triangles.assign(fitted.triangles.size(), 0);
    double u0 = 1.0, v0 = 1.0, u1 = 0.0, v1 = 0.0;
    for (std::size_t i = 0; i < fitted.triangles.size(); ++i) {
        const glm::uvec3& t = fitted.triangles[i];
        if (!near(fitted.positions[t.x]) && !near(fitted.positions[t.y]) && !near(fitted.positions[t.z])) continue;
        area.triangles[i] = 1;
        for (const std::uint32_t k : {t.x, t.y, t.z}) {
            u0 = std::min(u0, fitted.uvs[k].x), u1 = std::max(u1, fitted.uvs[k].x);
            v0 = std::min(v0, fitted.uvs[k].y), v1 = std::max(v1, fitted.uvs[k].y);
        }
    }
    if (u1 < u0) return area;
    // Aligned to the fill's quarter resolution, with room for the feather.
    constexpr int margin = 8;
    const int x0 = std::max(0, (static_cast<int>(u0 * size.width) - margin) / 4 * 4);
    const int y0 = std::max(0, (static_cast<int>(v0 * size.height) - margin) / 4 * 4);
    const int x1 = std::min(size.width, static_cast<int>(std::ceil(u1 * size.width)) + margin);
    const int y1 = std::min(size.height, static_cast<int>(std::ceil(v1 * size.height)) + margin);
    area.box = cv::Rect(x0, y0, x1 - x0, y1 - y0);
    return area;
}

// Repaints the texels `role` says with the skin round them: continued by pull-push from the texels it calls skin
// (only texels that took a photo are skin), with the skin layer's fine detail (tables.skinDetail), feathered at the
// edge. Only the area's triangles are asked. `role(texel, x, y)` must be safe to call from several threads. Returns
// how many texels were repainted at half weight or more.
template <typename Role>
int repaintWithSkin(PhotoTexture& texture, const Mesh& fitted, const HeadFit& fit, const PhotoTextureOptions& options,
                    const TextureTables& tables, const RepaintArea& area, const Role& role) {
    if (texture.texture.size() != tables.full().size || !tables.fits(fitted))
        throw BoothError(ErrorKind::Internal, "", "texture: the texel tables were made for another mesh or size");
    const TexelMap& map = tables.full();
    const cv::Rect box = area.box & cv::Rect(cv::Point(0, 0), map.size);
    if (box.empty()) return 0;
    const cv::Size size = box.size();
    // The fill runs at a quarter of the resolution (the skin's colour varies slowly; its detail is added at full
    // resolution): each cell of 4 x 4 texels sums its skin texels' colours and its repaint weights (one thread a row
    // of cells, so that no two write the same cell).
    const cv::Size small((size.width + 3) / 4, (size.height + 3) / 4);
    cv::Mat smallColour(small, CV_32FC3, cv::Scalar::all(0)), smallWeight(small, CV_32F, cv::Scalar(0));
    cv::Mat smallTarget(small, CV_32F, cv::Scalar(0)), smallTargetMax(small, CV_32F, cv::Scalar(0));
    cv::Mat target(size, CV_32F, cv::Scalar(0));
    // Per triangle of the area, the head's point and both photos' pixels over its texels (per texel, the side photo's
    // shifted reading and the barycentric sums cost more than all else the repaint does).
    std::vector<TexelToHead> toHead(fitted.triangles.size());
    {
        std::vector<glm::dvec2> frontPx, sidePx;
        for (const glm::dvec3& v : fitted.positions) {
            const cv::Point2d f = fit.front.toPixel({v.x, v.y}), sd = sidePhotoPoint(fit, options, v);
            frontPx.emplace_back(f.x, f.y);
            sidePx.emplace_back(sd.x, sd.y);
        }
        for (std::size_t ti = 0; ti < fitted.triangles.size(); ++ti) {
            if (!area.triangles[ti]) continue;
            const glm::uvec3& t = fitted.triangles[ti];
            std::array<glm::dvec2, 3> p;
            if (!texelCorners(fitted, t, map.size, p)) continue;
            const auto over = [&](const auto& a, int c) { return affineOver(p, a[t.x][c], a[t.y][c], a[t.z][c]); };
            toHead[ti] = {over(fitted.positions, 0), over(fitted.positions, 1), over(fitted.positions, 2),
                          {over(frontPx, 0), over(frontPx, 1), over(sidePx, 0), over(sidePx, 1)}};
        }
    }
    cv::parallel_for_(cv::Range(0, small.height), [&](const cv::Range& cells) {
        for (int y = cells.start * 4; y < std::min(size.height, cells.end * 4); ++y) {
            const int ty = box.y + y;
            const int* tri = map.triangle.ptr<int>(ty) + box.x;
            const unsigned char* src = texture.source.ptr<unsigned char>(ty) + box.x;
            const cv::Vec3b* in = texture.texture.ptr<cv::Vec3b>(ty) + box.x;
            cv::Vec3f* cellColour = smallColour.ptr<cv::Vec3f>(y / 4);
            float* cellWeight = smallWeight.ptr<float>(y / 4);
            float* cellTarget = smallTarget.ptr<float>(y / 4);
            float* cellTargetMax = smallTargetMax.ptr<float>(y / 4);
            for (int x = 0; x < size.width; ++x) {
                if (tri[x] < 0 || !area.triangles[static_cast<std::size_t>(tri[x])]) continue;
                const TexelToHead& a = toHead[static_cast<std::size_t>(tri[x])];
                const auto fx = static_cast<float>(box.x + x), fy = static_cast<float>(ty);
                PhotoTexel texel;
                texel.head = {a.x.at(fx, fy), a.y.at(fx, fy), a.z.at(fx, fy)};
                texel.seen = src[x] == PhotoTexture::Front || src[x] == PhotoTexture::Side;
                texel.front = src[x] == PhotoTexture::Front;
                if (texel.front) texel.pixel = {a.photo.fu.at(fx, fy), a.photo.fv.at(fx, fy)};
                else if (texel.seen) texel.pixel = {a.photo.su.at(fx, fy), a.photo.sv.at(fx, fy)};
                const TexelRole r = role(texel, box.x + x, ty);
                if (r.skin && texel.seen) {
                    cellColour[x / 4] += cv::Vec3f(in[x][0], in[x][1], in[x][2]);
                    cellWeight[x / 4] += 1.0f;
                } else if (r.repaint > 0.0f) {
                    target.at<float>(y, x) = r.repaint;
                    cellTarget[x / 4] += r.repaint / 16.0f;
                    cellTargetMax[x / 4] = std::max(cellTargetMax[x / 4], r.repaint);
                }
            }
        }
    });
    const int repainted = cv::countNonZero(target >= 0.5f);
    if (cv::countNonZero(smallTarget) == 0 || cv::countNonZero(smallWeight) == 0) return 0;
    for (int y = 0; y < small.height; ++y)
        for (int x = 0; x < small.width; ++x)
            if (float& w = smallWeight.at<float>(y, x); w > 0.0f) {
                smallColour.at<cv::Vec3f>(y, x) /= w;
                w /= 16.0f;
            }
    pullPushFill(smallColour, smallWeight);
    // The edge feathered over a few texels at that resolution, so that no hard edge is left where the photo's hair
    // or clothes ended.
    cv::GaussianBlur(smallTarget, smallTarget, cv::Size(), 1.0);
    // Both read at full resolution, bilinearly, and only where the feathered edge reaches.
    const auto mix = [&](const cv::Mat& m, auto zero, int x, int y) {
        using V = decltype(zero);
        const float fx = std::clamp((static_cast<float>(x) + 0.5f) / 4.0f - 0.5f, 0.0f, static_cast<float>(small.width - 1));
        const float fy = std::clamp((static_cast<float>(y) + 0.5f) / 4.0f - 0.5f, 0.0f, static_cast<float>(small.height - 1));
        const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
        const int x1 = std::min(x0 + 1, small.width - 1), y1 = std::min(y0 + 1, small.height - 1);
        const float ax = fx - static_cast<float>(x0), ay = fy - static_cast<float>(y0);
        return V((1.0f - ay) * ((1.0f - ax) * m.at<V>(y0, x0) + ax * m.at<V>(y0, x1)) +
                 ay * ((1.0f - ax) * m.at<V>(y1, x0) + ax * m.at<V>(y1, x1)));
    };
    // The cells the feathered edge reaches (a texel reads the 2 x 2 cells round it), and the most a texel in the
    // cells round each was repainted by.
    cv::Mat reached, edgeMax;
    cv::dilate(smallTarget > 0.0f, reached, cv::Mat::ones(3, 3, CV_8U));
    cv::dilate(smallTargetMax, edgeMax, cv::Mat::ones(3, 3, CV_8U));
    const cv::Mat& detail = tables.skinDetail();
    cv::parallel_for_(cv::Range(0, size.height), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
            const int ty = box.y + y;
            const int* tri = map.triangle.ptr<int>(ty) + box.x;
            const float* t = target.ptr<float>(y);
            const unsigned char* near = reached.ptr<unsigned char>(y / 4);
            const float* edge = edgeMax.ptr<float>(y / 4);
            cv::Vec3b* o = texture.texture.ptr<cv::Vec3b>(ty) + box.x;
            for (int x = 0; x < size.width; ++x) {
                if (!near[x / 4]) continue;
                // Texels between the UV islands (no triangle) hold the fill's bleed of the colours beside them, which
                // the renderer's filtering reads at the islands' edges: they take the most any texel round them
                // was repainted by, so that no rim of the old colour is left round what was.
                const float wx = tri[x] >= 0 ? std::max(t[x], mix(smallTarget, 0.0f, x, y)) : edge[x / 4];
                if (wx <= 0.0f) continue;
                cv::Vec3f skin = mix(smallColour, cv::Vec3f(), x, y);
                if (!detail.empty()) {
                    const cv::Vec<schar, 3> d = detail.at<cv::Vec<schar, 3>>(ty, box.x + x);
                    skin += cv::Vec3f(d[0], d[1], d[2]);
                }
                for (int c = 0; c < 3; ++c) o[x][c] = cv::saturate_cast<unsigned char>(wx * skin[c] + (1.0f - wx) * o[x][c]);
            }
        }
    });
    return repainted;
}

// How far past a repaint's region the texels of skin are sources of its fill (mm).
constexpr double kSkinAroundMm = 40.0;

// 1 up to the edge, fading out (smoothly) over `fadeMm` beyond it (`beyond`: how far past the edge, in mm).
double fadeOutPast(double beyond, double fadeMm) {
    if (beyond <= 0.0) return 1.0;
    return fadeMm > 0.0 ? 1.0 - smoothstep(beyond / fadeMm) : 0.0;
}

}  // namespace

int skinOverHairBesideFace(PhotoTexture& texture, const Mesh& fitted, const HeadFit& fit, const ColourMatchMasks& notSkin,
                           const FaceSides& sides, const PhotoTextureOptions& options, const TextureTables& tables) {
    if (notSkin.frontNotSkin.empty() && notSkin.sideNotSkin.empty()) return 0;
    // How much a point is on the face's sides: 1 inside, fading out above, behind and under them.
    const auto onSides = [&](const glm::dvec3& p) {
        if (std::abs(p.x) < sides.innerX) return 0.0;
        return fadeOutPast(p.y - sides.topY, sides.fadeMm) * fadeOutPast(sides.bottomY - p.y, sides.fadeMm) *
               fadeOutPast(sides.frontOfZ - p.z, sides.fadeMm);
    };
    // The face's height and a little more: the sides and the skin round them the fill continues.
    const RepaintArea area = repaintArea(fitted, texture.texture.size(), [&](const glm::dvec3& p) {
        return p.y > sides.bottomY - sides.fadeMm - kSkinAroundMm && p.y < sides.topY + sides.fadeMm + kSkinAroundMm;
    });
    // Each texel that took a photo: skin (a source of the fill) or hair on the face's sides (repainted, by how much).
    return repaintWithSkin(texture, fitted, fit, options, tables, area, [&](const PhotoTexel& t, int, int) {
        if (!t.seen) return TexelRole{};
        const cv::Mat& hair = t.front ? notSkin.frontNotSkin : notSkin.sideNotSkin;
        if (isSkin(hair, static_cast<float>(t.pixel.x), static_cast<float>(t.pixel.y))) return TexelRole{true, 0.0f};
        return TexelRole{false, static_cast<float>(onSides(t.head))};
    });
}

int skinOverClothesOnNeck(PhotoTexture& texture, const Mesh& fitted, const HeadFit& fit, const ColourMatchMasks& hair,
                          const NeckClothes& neck, const PhotoTextureOptions& options, const TextureTables& tables) {
    if (texture.texture.empty()) return 0;
    const auto topAt = [&](double z) {
        const double behind = neck.frontZ > neck.backZ ? smoothstep(std::clamp((neck.frontZ - z) / (neck.frontZ - neck.backZ), 0.0, 1.0)) : 0.0;
        return std::pair{neck.topY + behind * (neck.backTopY - neck.topY), behind};
    };
    // The neck and the skin above it the fill continues.
    const RepaintArea area = repaintArea(fitted, texture.texture.size(), [&](const glm::dvec3& p) {
        return p.y < topAt(p.z).first + neck.fadeMm + kSkinAroundMm;
    });
    if (area.box.empty()) return 0;
    // The texture's colours in CIE L*a*b* (8-bit: L 0..255, a and b offset by 128), against the visitor's skin.
    cv::Mat lab;
    cv::cvtColor(texture.texture(area.box), lab, cv::COLOR_BGR2Lab);
    const auto skinDistance = [&](int x, int y) {
        const cv::Vec3b c = lab.at<cv::Vec3b>(y - area.box.y, x - area.box.x);
        const double dl = neck.lightnessWeight * (c[0] * 100.0 / 255.0 - neck.skinLab[0]);
        const double da = c[1] - 128.0 - neck.skinLab[1], db = c[2] - 128.0 - neck.skinLab[2];
        return std::sqrt(dl * dl + da * da + db * db);
    };
    return repaintWithSkin(texture, fitted, fit, options, tables, area, [&](const PhotoTexel& t, int x, int y) {
        const auto [top, behind] = topAt(t.head.z);
        const bool under = t.head.y < top + neck.fadeMm;
        if (t.head.y > top + neck.fadeMm + kSkinAroundMm || (!under && !t.seen)) return TexelRole{};
        if (t.seen && (!under || neck.keepHairBehind || behind < 0.5)) {
            const cv::Mat& h = t.front ? hair.frontNotSkin : hair.sideNotSkin;
            if (!isSkin(h, static_cast<float>(t.pixel.x), static_cast<float>(t.pixel.y))) return TexelRole{};  // hair stays
        }
        if (skinDistance(x, y) <= neck.maxSkinDistance) return TexelRole{t.seen, 0.0f};
        return TexelRole{false, under ? static_cast<float>(fadeOutPast(t.head.y - top, neck.fadeMm)) : 0.0f};
    });
}

void addBaseLayerDetail(PhotoTexture& texture, const cv::Mat& detail) {
    if (texture.texture.empty() || detail.empty() || detail.size() != texture.texture.size()) return;
    if (detail.type() != CV_8SC3) throw BoothError(ErrorKind::Internal, "", "texture: the skin detail must be CV_8SC3");
    // Feathered: the made-up texels take all of it, those a photo saw none, with a soft edge between (the mask
    // blurred at an eighth of the size: the edge needs no more).
    constexpr int kShrink = 8;
    cv::Mat filled, small;
    cv::compare(texture.source, PhotoTexture::Filled, filled, cv::CMP_EQ);
    cv::resize(filled, small, cv::Size(), 1.0 / kShrink, 1.0 / kShrink, cv::INTER_AREA);
    small.convertTo(small, CV_32F, 1.0 / 255.0);
    cv::GaussianBlur(small, small, cv::Size(), 1.5);
    // The weight read bilinearly from the small mask (cells' centres at (i + 0.5) * kShrink), row by row on the
    // threads, touching only the texels where it is above zero (most of the texture was seen and stays as it is).
    const cv::Size size = texture.texture.size();
    std::vector<UpsampleTap> columns;
    for (int x = 0; x < size.width; ++x) columns.push_back(upsampleTap(x, small.cols, kShrink));
    cv::parallel_for_(cv::Range(0, size.height), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
            const UpsampleTap row = upsampleTap(y, small.rows, kShrink);
            const float* a = small.ptr<float>(row.i0);
            const float* b = small.ptr<float>(row.i1);
            const cv::Vec<schar, 3>* d = detail.ptr<cv::Vec<schar, 3>>(y);
            cv::Vec3b* t = texture.texture.ptr<cv::Vec3b>(y);
            for (int x = 0; x < size.width; ++x) {
                const UpsampleTap& c = columns[static_cast<std::size_t>(x)];
                const float w = (1.0f - row.f) * (a[c.i0] + c.f * (a[c.i1] - a[c.i0])) + row.f * (b[c.i0] + c.f * (b[c.i1] - b[c.i0]));
                if (w <= 0.0f) continue;
                for (int k = 0; k < 3; ++k) t[x][k] = cv::saturate_cast<unsigned char>(t[x][k] + w * d[x][k]);
            }
        }
    });
}

}  // namespace avatarbooth
