// Fitting the synthetic visitor, whose true shape is known: with ground-truth landmarks the fitted head must be
// within 1 % of head height (RMS over the head's vertices, after a similarity alignment).
#include "truth_measurements.h"

#include "fit/face/landmarks68.h"
#include "fit/fit_pipeline.h"
#include "fit/head/head_fit.h"
#include "fit/head/shape_compare.h"
#include "sim/synthetic_visitor.h"

#include <gtest/gtest.h>

using namespace avatarbooth;

namespace {

MeshRenderer& renderer() {
    static MeshRenderer r;
    return r;
}

// Head vertices: above the throat (the neck below is not a part of the head a photo pins down).
std::vector<bool> headRegion(const BaseHead& base) {
    std::vector<bool> include(base.mesh.positions.size());
    for (std::size_t i = 0; i < include.size(); ++i) include[i] = base.mesh.positions[i].y > -130.0;
    return include;
}

double headHeight(const BaseHead& base, const Mesh& mesh) {
    return mesh.positions[base.sideFeatures.at("top_of_head")].y - mesh.positions[base.frontFeatures.at("ibug_08")].y;
}

}  // namespace

class SyntheticFit : public ::testing::TestWithParam<unsigned> {};

TEST_P(SyntheticFit, GroundTruthLandmarksRecoverTheShapeWithinOnePercent) {
    const BaseHead& base = builtinBaseHead();
    SyntheticVisitorOptions o;
    o.seed = GetParam();
    o.sideNoseImageRight = GetParam() % 2 == 1;
    o.textureSize = 256;  // the paint does not matter here
    const SyntheticVisitor v = makeSyntheticVisitor(base, renderer(), o);
    const HeadFit fit = fitHead(base, test::truthMeasurements(v, o.sideNoseImageRight), defaultHeadFitOptions());

    const double height = headHeight(base, v.truthMesh);
    const double before = rmsAfterSimilarity(base.mesh, v.truthMesh, headRegion(base));
    const double after = rmsAfterSimilarity(fit.mesh, v.truthMesh, headRegion(base));
    std::printf("seed %u: head height %.1f mm, base head vs truth %.2f mm (%.2f %%), fitted vs truth %.2f mm (%.2f %%)\n",
                GetParam(), height, before, 100 * before / height, after, 100 * after / height);
    EXPECT_LT(after / height, 0.01);
    EXPECT_LT(after, before) << "the fit must improve on the base head";
    // Each view's warp hits its targets exactly; only y, shared by the two views and blended, may differ a little.
    for (const auto& r : fit.residuals) {
        EXPECT_LT(std::abs(r.view == "front" ? r.fitted.x - r.measured.x : r.fitted.x - r.measured.x), 1e-6) << r.name;
        EXPECT_LT(r.errorMm, 1.5) << r.view << " " << r.name;
    }
}

INSTANTIATE_TEST_SUITE_P(Seeds, SyntheticFit, ::testing::Values(1u, 2u, 3u, 4u));

// The whole automatic pipeline on the synthetic visitor's photos (dlib landmarks, silhouettes, profile
// landmarks): the fitted head within 3 % of head height of the truth.
// Measured: 2.6 % (seed 1) and 2.0 % (seed 2). Note: for seed 1 the unfitted base head is at 2.25 %, so the fit
// from detected points does not yet beat it there (see the issue notes).
TEST(SyntheticFitDetected, DetectedLandmarksRecoverTheShapeWithinThreePercent) {
    const BaseHead& base = builtinBaseHead();
    const FitPipeline pipeline{FitSettings{}};
    for (const unsigned seed : {1u, 2u}) {
        SyntheticVisitorOptions o;
        o.seed = seed;
        o.sideNoseImageRight = seed % 2 == 0;
        const SyntheticVisitor v = makeSyntheticVisitor(base, renderer(), o);
        for (const bool withPlate : {true, false}) {
            const FitOutcome out = pipeline.fit(v.front, v.side, withPlate ? v.background : cv::Mat());
            const double height = headHeight(base, v.truthMesh);
            const double error = rmsAfterSimilarity(out.fit.mesh, v.truthMesh, headRegion(base));
            std::printf("seed %u (%s plate): fitted vs truth %.2f mm (%.2f %% of head height)\n", seed,
                        withPlate ? "with" : "no", error, 100 * error / height);
            EXPECT_LT(error / height, 0.03) << "seed " << seed;
            // dlib's points land near the true ones: up to 12.5 px measured on the painted eyes (a ~400 px tall head),
            // because the paint is drawn around the design table, not at the feature vertices themselves.
            double worst = 0;
            for (int k = 36; k <= 47; ++k) {
                const auto& truth = v.frontLandmarks.at(landmarkName(k));
                worst = std::max(worst, cv::norm(out.frontLandmarks.points[static_cast<std::size_t>(k)] - truth));
            }
            EXPECT_LT(worst, 15.0) << "eye landmarks, seed " << seed;
        }
    }
}
