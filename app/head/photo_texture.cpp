// Photo texturing: per-texel projection into both photos, angle weighting, colour matching, hole filling.
#include "head/photo_texture.h"

#include "head/surface_texels.h"

#include <opencv2/imgproc.hpp>

#include <cmath>

namespace avatarbooth {

void pullPushFill(cv::Mat& colour, cv::Mat& weight) {
    // Pull: average known texels into ever coarser levels. Push: fill the unknown texels of each finer level
    // from the level below it, so holes take a smooth mean of what surrounds them.
    if (colour.rows <= 1 || colour.cols <= 1) return;
    cv::Mat w3;
    cv::merge(std::vector<cv::Mat>{weight, weight, weight}, w3);
    cv::Mat premultiplied = colour.mul(w3);
    cv::Mat coarseColour, coarseWeight;
    cv::resize(premultiplied, coarseColour, cv::Size((colour.cols + 1) / 2, (colour.rows + 1) / 2), 0, 0, cv::INTER_AREA);
    cv::resize(weight, coarseWeight, coarseColour.size(), 0, 0, cv::INTER_AREA);
    cv::Mat cw3;
    cv::merge(std::vector<cv::Mat>{coarseWeight, coarseWeight, coarseWeight}, cw3);
    cv::Mat coarse;
    cv::divide(coarseColour, cv::max(cw3, 1e-6), coarse);
    cv::Mat known = coarseWeight > 1e-6;
    cv::Mat coarseW = cv::Mat::zeros(coarseWeight.size(), CV_32F);
    coarseW.setTo(1.0f, known);
    if (cv::countNonZero(known) < coarse.rows * coarse.cols) pullPushFill(coarse, coarseW);
    cv::Mat up;
    cv::resize(coarse, up, colour.size(), 0, 0, cv::INTER_LINEAR);
    // Keep known texels; blend in the coarse fill where the weight is partial.
    cv::Mat clamped = cv::min(weight, 1.0f);
    cv::Mat c3;
    cv::merge(std::vector<cv::Mat>{clamped, clamped, clamped}, c3);
    colour = colour.mul(c3) + up.mul(cv::Scalar::all(1.0) - c3);
    weight.setTo(1.0f);
}

namespace {

// Samples a photo (bilinear) at per-texel pixel positions; `valid` says where the point fell on the silhouette.
cv::Mat samplePhoto(const cv::Mat& photo, const cv::Mat& mask, const cv::Mat& mapX, const cv::Mat& mapY, cv::Mat& valid) {
    cv::Mat sampled, maskSampled;
    cv::remap(photo, sampled, mapX, mapY, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    cv::remap(mask, maskSampled, mapX, mapY, cv::INTER_NEAREST, cv::BORDER_CONSTANT);
    valid = maskSampled > 0;
    cv::Mat f;
    sampled.convertTo(f, CV_32FC3);
    return f;
}

}  // namespace

PhotoTexture textureFromPhotos(const Mesh& fitted, const HeadFit& fit, const cv::Mat& front, const cv::Mat& frontMask,
                               const cv::Mat& side, const cv::Mat& sideMask, const PhotoTextureOptions& options) {
    const cv::Size size(options.size, options.size);
    const SurfaceTexels texels = sampleSurfaceTexels(fitted, fitted.vertexNormals(), cachedTexelMap(fitted, size));
    cv::Mat fx(size, CV_32F), fy(size, CV_32F), sx(size, CV_32F), sy(size, CV_32F);
    cv::Mat wFront(size, CV_32F, cv::Scalar(0)), wSide(size, CV_32F, cv::Scalar(0));
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            const cv::Vec3f p = texels.position.at<cv::Vec3f>(y, x);
            const cv::Vec3f n = texels.normal.at<cv::Vec3f>(y, x);
            const cv::Point2d f = fit.front.toPixel({p[0], p[1]});
            const cv::Point2d s = fit.side.toPixel({p[2], p[1]});
            fx.at<float>(y, x) = static_cast<float>(f.x);
            fy.at<float>(y, x) = static_cast<float>(f.y);
            sx.at<float>(y, x) = static_cast<float>(s.x);
            sy.at<float>(y, x) = static_cast<float>(s.y);
            if (!texels.covered.at<unsigned char>(y, x)) continue;
            const auto strict = [&](double c) { return options.angleStrictness == 2.0 ? c * c : std::pow(c, options.angleStrictness); };
            // The front photo sees surfaces facing +z; the side photo sees one side, and stands in (mirrored) for
            // the other: the orthographic side view of (z, y) is the same for x and -x.
            wFront.at<float>(y, x) = static_cast<float>(strict(std::max(0.0f, n[2])));
            wSide.at<float>(y, x) = static_cast<float>(strict(std::abs(n[0])));
        }
    }
    cv::Mat frontValid, sideValid;
    const cv::Mat frontColour = samplePhoto(front, frontMask, fx, fy, frontValid);
    cv::Mat sideColour = samplePhoto(side, sideMask, sx, sy, sideValid);
    wFront.setTo(0.0f, ~frontValid);
    wSide.setTo(0.0f, ~sideValid);

    // The photos differ in exposure and white balance: match the side photo's colour to the front's where both
    // see the surface well (per-channel gain).
    const cv::Mat overlap = (wFront > 0.15f) & (wSide > 0.15f);
    if (cv::countNonZero(overlap) > 200) {
        const cv::Scalar mf = cv::mean(frontColour, overlap), ms = cv::mean(sideColour, overlap);
        cv::Scalar gain;
        for (int c = 0; c < 3; ++c) gain[c] = std::clamp(mf[c] / std::max(ms[c], 1.0), 0.6, 1.6);
        sideColour = sideColour.mul(cv::Scalar(gain[0], gain[1], gain[2]));
    }

    cv::Mat weight = wFront + wSide;
    cv::Mat wf3, ws3, w3;
    cv::merge(std::vector<cv::Mat>{wFront, wFront, wFront}, wf3);
    cv::merge(std::vector<cv::Mat>{wSide, wSide, wSide}, ws3);
    cv::merge(std::vector<cv::Mat>{weight, weight, weight}, w3);
    cv::Mat colour;
    cv::divide(frontColour.mul(wf3) + sideColour.mul(ws3), cv::max(w3, 1e-6), colour);
    // Texels seen only at grazing angles count as partly unknown, so the fill blends into them.
    cv::Mat confidence = cv::min(weight * 4.0f, 1.0f);
    const int covered = cv::countNonZero(texels.covered);
    const int seen = cv::countNonZero((confidence > 0.05f) & texels.covered);
    confidence.setTo(0.0f, confidence <= 0.05f);
    pullPushFill(colour, confidence);

    PhotoTexture out;
    colour.convertTo(out.texture, CV_8UC3);
    out.seenFraction = covered > 0 ? static_cast<double>(seen) / covered : 0.0;
    return out;
}

}  // namespace avatarbooth
