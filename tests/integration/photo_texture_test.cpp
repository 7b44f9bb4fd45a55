// The texture step on the synthetic visitor, whose painted texture is known: photographed without shading, the
// head fitted from its true landmarks and textured from the two photos must give back the paint where they see it.
#include "truth_measurements.h"

#include "fit/head/head_fit.h"
#include "fit/head/photo_texture.h"
#include "fit/head/surface_texels.h"
#include "sim/synthetic_visitor.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

using namespace avatarbooth;

namespace {

MeshRenderer& renderer() {
    static MeshRenderer r;
    return r;
}

// The face: texels in front of the eyes' plane less 35 mm and facing forward (where the paint has its features).
cv::Mat faceTexels(const BaseHead& base, int size) {
    const SurfaceTexels texels = sampleSurfaceTexels(base.mesh, base.mesh.vertexNormals(), cv::Size(size, size));
    const double faceDepth = base.eyeMidpoint().z - 35.0;
    cv::Mat face(size, size, CV_8U, cv::Scalar(0));
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const cv::Vec3f p = texels.position.at<cv::Vec3f>(y, x), n = texels.normal.at<cv::Vec3f>(y, x);
            if (texels.covered.at<unsigned char>(y, x) && p[2] > faceDepth && n[2] > 0.25f) face.at<unsigned char>(y, x) = 255;
        }
    return face;
}

double meanAbsError(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
    cv::Mat d;
    cv::absdiff(a, b, d);
    const cv::Scalar m = cv::mean(d, mask);
    return (m[0] + m[1] + m[2]) / 3.0;
}

}  // namespace

// Measured: mean error over the seen face 2.32 (seed 1) and 2.81 (seed 2) levels of 255, over everything seen 3.44
// and 4.21, with the side photo's exposure matched locally (PhotoTextureOptions::exposureSmoothing; one gain for the
// whole photo: 2.77 and 3.41, 3.79 and 4.53). The side photo takes the face's sides from 51 degrees on
// (PhotoTextureOptions::frontPreference 1.5): lit, as in the booth, the front photo's side of the seam is the darker
// (a dark band down every FRMDB profile's cheek when the seam lay at 63 degrees). The former texturing
// (both photos averaged by cos^2 of the angle, no visibility test) measured 3.1 and 3.7 on the face: the side photo's
// nostrils and nose edge showed beside the front photo's.
TEST(PhotoTextureSynthetic, TextureMatchesThePaintWhereThePhotosSeeIt) {
    const BaseHead& base = builtinBaseHead();
    for (const unsigned seed : {1u, 2u}) {
        SyntheticVisitorOptions o;
        o.seed = seed;
        o.sideNoseImageRight = seed % 2 == 1;
        o.lit = false;  // the photos show the paint itself, so the texture can be compared with it
        const SyntheticVisitor v = makeSyntheticVisitor(base, renderer(), o);
        const PhotoMeasurements m = test::truthMeasurements(v, o.sideNoseImageRight);
        const HeadFit fit = fitHead(base, m, defaultHeadFitOptions());
        PhotoTextureOptions to;
        to.size = o.textureSize;
        const PhotoTexture t = textureFromPhotos(fit.mesh, fit, v.front, m.frontMask, v.side, m.sideMask, to);

        const cv::Mat seen = t.source != PhotoTexture::Filled;
        const cv::Mat face = faceTexels(base, to.size);
        const double faceError = meanAbsError(t.texture, v.texture, seen & face);
        const double seenError = meanAbsError(t.texture, v.texture, seen);
        std::printf("seed %u: seen %.1f %% of the head; mean error on the face %.2f, everywhere seen %.2f\n", seed,
                    100.0 * t.seenFraction, faceError, seenError);
        EXPECT_GT(t.seenFraction, 0.85) << "seed " << seed;
        EXPECT_GT(cv::countNonZero(seen & face), cv::countNonZero(face) * 95 / 100) << "the photos see almost all the face";
        EXPECT_LT(faceError, 3.0) << "seed " << seed;
        EXPECT_LT(seenError, 5.0) << "seed " << seed;
        // The fill of the unseen rest stays among the head's colours (hair, skin), not black.
        cv::Mat grey;
        cv::cvtColor(t.texture, grey, cv::COLOR_BGR2GRAY);
        const double fillGrey = cv::mean(grey, ~seen)[0];
        std::printf("  mean grey of the filled texels %.1f (hair about 40, skin about 160)\n", fillGrey);
        EXPECT_GT(fillGrey, 50.0) << "seed " << seed;
    }
}
