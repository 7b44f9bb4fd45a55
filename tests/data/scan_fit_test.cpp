// The real head scan (Lee Perry-Smith, CC BY 3.0): fit its rendered front (yaw 0) and side (yaw +90) views and
// compare the fitted head's surface with the scan's head region, after a similarity alignment (ICP with scale).
#include "test_paths.h"

#include "fit/export/glb.h"
#include "fit/head/shape_compare.h"
#include "booth/session_folder.h"
#include "fit/fit_pipeline.h"
#include "render/mesh_renderer.h"

#include <gtest/gtest.h>
#include <opencv2/flann.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cmath>

namespace fs = std::filesystem;
using namespace avatarbooth;

namespace {

// RMS distance from the points to the nearest scan vertices, after aligning the points onto the scan by
// iterated closest points with a similarity (scale included: the scan's unit is not stated).
// Returns the RMS in scan units; *scale receives the total scale from points to scan.
double icpRms(std::vector<glm::dvec3> points, const std::vector<glm::dvec3>& scan, Similarity initial, double* scale,
              std::vector<double>* distances = nullptr) {
    cv::Mat data(static_cast<int>(scan.size()), 3, CV_32F);
    for (int i = 0; i < data.rows; ++i)
        for (int c = 0; c < 3; ++c) data.at<float>(i, c) = static_cast<float>(scan[static_cast<std::size_t>(i)][c]);
    cv::flann::Index index(data, cv::flann::KDTreeIndexParams(4));
    for (auto& p : points) p = initial.apply(p);
    *scale = initial.scale;
    double rms = 0.0;
    for (int iteration = 0; iteration < 40; ++iteration) {
        cv::Mat query(static_cast<int>(points.size()), 3, CV_32F), indices, dists;
        for (int i = 0; i < query.rows; ++i)
            for (int c = 0; c < 3; ++c) query.at<float>(i, c) = static_cast<float>(points[static_cast<std::size_t>(i)][c]);
        index.knnSearch(query, indices, dists, 1, cv::flann::SearchParams(64));
        std::vector<glm::dvec3> targets;
        double sum = 0.0;
        for (int i = 0; i < query.rows; ++i) {
            targets.push_back(scan[static_cast<std::size_t>(indices.at<int>(i))]);
            sum += dists.at<float>(i);
        }
        rms = std::sqrt(sum / query.rows);
        if (distances) {
            distances->resize(points.size());
            for (int i = 0; i < query.rows; ++i) (*distances)[static_cast<std::size_t>(i)] = std::sqrt(dists.at<float>(i));
        }
        const Similarity step = alignSimilarity(points, targets);
        *scale *= step.scale;
        for (auto& p : points) p = step.apply(p);
    }
    return rms;
}

}  // namespace

// The bar is 3 % of head height; the fit must also come nearer the scan than the unfitted base head (the
// product's, MakeHuman's), or it has learnt nothing from the photos. (measure.py's face-region figures, the issue's
// measure of likeness, are in tests/data/likeness_data_test.cpp.)
TEST(ScanFit, FittedHeadIsNearerTheScanThanTheBaseHead) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    const fs::path dir = test::sharedData() / "scan_lee_perry_smith";
    if (findMakeHumanBaseHead().empty()) GTEST_SKIP() << "the MakeHuman base head was not built";
    const auto product = productBaseHead();
    const FitPipeline pipeline{FitSettings{}, *product};
    const FitPhotoFiles inputs{dir / "renders" / "LeePerrySmith_yaw+000_rgb.png", dir / "renders" / "LeePerrySmith_yaw+090_rgb.png", {}};
    static MeshRenderer renderer;
    const FitOutcome out = pipeline.fit(inputs);
    writeSessionFolder(out, {inputs}, test::scratchDir("scan_fit") / "session", renderer);

    const BaseHead& base = pipeline.baseHead();
    const Mesh& fitted = out.fit.mesh;
    const auto at = [&](const std::string& n) { return fitted.positions[base.sideFeatures.at(n)]; };
    const double headHeight = at("top_of_head").y - fitted.positions[base.frontFeatures.at("ibug_08")].y;
    // The head region of the fitted mesh: above the chin's level at the front, above the ear-to-chin line behind.
    std::vector<glm::dvec3> head;
    const double chinY = fitted.positions[base.frontFeatures.at("ibug_08")].y;
    for (const auto& p : fitted.positions)
        if (p.y > chinY + 10.0) head.push_back(p);

    // The scan's head: its vertices above its chin (nose tip at about (0, 1.1, 2.59); chin ~1.3 units below).
    const Mesh scan = readGlbMesh(dir / "LeePerrySmith.glb");
    std::vector<glm::dvec3> scanHead;
    glm::dvec3 noseScan(0.0, -1e9, -1e9);
    for (const auto& p : scan.positions)
        if (p.z > noseScan.z) noseScan = p;
    // The scan's surface, sampled densely (every triangle on a barycentric grid, about 1 mm apart) so the
    // nearest sample is the nearest surface point to within a fraction of a millimetre, not the nearest vertex
    // (about 5 mm apart, which would put a floor of several millimetres under every distance).
    constexpr int kSteps = 5;
    for (const auto& t : scan.triangles) {
        const glm::dvec3 a = scan.positions[t.x], b = scan.positions[t.y], c = scan.positions[t.z];
        for (int i = 0; i <= kSteps; ++i)
            for (int j = 0; i + j <= kSteps; ++j) {
                const glm::dvec3 p = a + (b - a) * (double(i) / kSteps) + (c - a) * (double(j) / kSteps);
                // readGlbMesh gives millimetres of "metres": scan units x 1000
                if (p.y > noseScan.y - 1500.0) scanHead.push_back(p);
            }
    }
    // Initial guess: scale by head length, nose tips together.
    Similarity initial;
    const double scanLength = [&] {
        double lo = 1e18, hi = -1e18;
        for (const auto& p : scanHead) {
            if (std::abs(p.y - (noseScan.y + 300.0)) < 200.0) {
                lo = std::min(lo, p.z);
                hi = std::max(hi, p.z);
            }
        }
        return hi - lo;
    }();
    initial.scale = scanLength / (at("glabella").z - at("back_of_head").z);
    initial.translation = noseScan - initial.scale * at("nose_tip");
    double scale = 1.0;
    std::vector<double> fittedDistances;
    const double rmsScanUnits = icpRms(head, scanHead, initial, &scale, &fittedDistances);
    // In the fitted head's millimetres. Distances are to the nearest scan vertex (about 5 mm apart), so they
    // over-state the distance to the surface a little: the test errs on the strict side.
    const double rmsMm = rmsScanUnits / scale;
    std::printf("scan: fitted head vs scan surface %.2f mm RMS = %.2f %% of head height (%.0f mm)\n", rmsMm,
                100.0 * rmsMm / headHeight, headHeight);
    EXPECT_LT(rmsMm / headHeight, 0.03);

    // The same measure for the unfitted base head (scaled to the same size): the fit must do better than it.
    std::vector<glm::dvec3> baseHead;
    const double baseChin = base.mesh.positions[base.frontFeatures.at("ibug_08")].y;
    for (const auto& p : base.mesh.positions)
        if (p.y > baseChin + 10.0) baseHead.push_back(p);
    const auto baseAt = [&](const std::string& n) { return base.mesh.positions[base.sideFeatures.at(n)]; };
    Similarity baseInitial;
    baseInitial.scale = scanLength / (baseAt("glabella").z - baseAt("back_of_head").z);
    baseInitial.translation = noseScan - baseInitial.scale * baseAt("nose_tip");
    double baseScale = 1.0;
    std::vector<double> baseDistances;
    const double baseRmsMm = icpRms(baseHead, scanHead, baseInitial, &baseScale, &baseDistances) / baseScale;
    // Where the two differ, by region of the head (to see what the fit gets wrong).
    const auto regionReport = [&](const std::vector<glm::dvec3>& pts, const std::vector<double>& d, double s,
                                  const char* what) {
        const char* names[] = {"face", "top", "back", "sides", "lower"};
        double sums[5] = {}; int counts[5] = {};
        double zMax = -1e9;
        for (const auto& p : pts) zMax = std::max(zMax, p.z);
        for (std::size_t i = 0; i < pts.size(); ++i) {
            const auto& p = pts[i];
            int r = 3;
            if (p.y > 60) r = 1;
            else if (p.z > zMax - 70 && std::abs(p.x) < 60) r = 0;
            else if (p.z < -40) r = 2;
            else if (p.y < -60) r = 4;
            sums[r] += (d[i] / s) * (d[i] / s); counts[r]++;
        }
        std::printf("scan: %s by region:", what);
        for (int r = 0; r < 5; ++r) std::printf(" %s %.2f mm (%d)", names[r], counts[r] ? std::sqrt(sums[r] / counts[r]) : 0.0, counts[r]);
        std::printf("\n");
    };
    regionReport(head, fittedDistances, scale, "fitted");
    regionReport(baseHead, baseDistances, baseScale, "base");
    std::printf("scan: the unfitted base head vs scan surface %.2f mm RMS = %.2f %%\n", baseRmsMm, 100.0 * baseRmsMm / headHeight);
    EXPECT_LT(rmsMm, baseRmsMm);
}
