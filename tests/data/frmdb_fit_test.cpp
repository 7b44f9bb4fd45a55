// All eight FRMDB people (real photos, dark hair on a dark backdrop) fit without error, with both profile
// directions, with the product's base head (MakeHuman's) and without a fold; the overlays and previews are written
// for a person to look at, with the avatar's outline over the photo's (silhouette_front.jpg, silhouette_side.jpg).
#include "test_paths.h"

#include "fit/export/glb.h"
#include "booth/session_folder.h"
#include "common/landmark_names.h"
#include "fit/fit_pipeline.h"
#include "fit/head/ears.h"
#include "fit/head/folds.h"
#include "fit/parts/hair_part.h"
#include "render/mesh_renderer.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <limits>
#include <map>
#include <optional>
#include <cmath>
#include <cstdio>

namespace fs = std::filesystem;
using namespace avatarbooth;

namespace {

const FitPipeline& pipeline() {
    static const auto base = productBaseHead();
    static const FitPipeline p{FitSettings{}, *base};
    return p;
}

MeshRenderer& renderer() {
    static MeshRenderer r;
    return r;
}

// How well the avatar's silhouette (the head and its hair) covers the photo's above the brows, where the hair is:
// intersection over union of the two, the avatar drawn into the photo through the fit's frame (front: x, y; side:
// z, y). Both outlines are drawn on the photo into `overlay`.
double silhouetteAgreementAboveBrows(const FitOutcome& o, bool side, const fs::path& overlay) {
    const PhotoFrame& frame = side ? o.fit.side : o.fit.front;
    const cv::Mat& photo = side ? o.sideMask : o.frontMask;
    cv::Mat avatar = cv::Mat::zeros(photo.size(), CV_8U);
    const auto draw = [&](const Mesh& m) {
        for (const glm::uvec3& t : m.triangles) {
            cv::Point corners[3];
            for (int i = 0; i < 3; ++i) {
                const glm::dvec3& p = m.positions[t[i]];
                const cv::Point2d px = frame.toPixel(side ? glm::dvec2(p.z, p.y) : glm::dvec2(p.x, p.y));
                corners[i] = cv::Point(cvRound(px.x * 16), cvRound(px.y * 16));  // 4 bits of subpixel
            }
            cv::fillConvexPoly(avatar, corners, 3, cv::Scalar(255), cv::LINE_8, 4);
        }
    };
    draw(o.fit.mesh);
    for (const auto& part : o.parts)
        if (part.name == "hair") draw(part.mesh);
    double browY = -1e9;
    for (int k = 17; k <= 26; ++k)
        browY = std::max(browY, o.fit.mesh.positions[pipeline().baseHead().frontFeatures.at(landmarkName(k))].y);
    const cv::Rect above(0, 0, photo.cols, std::clamp(cvRound(frame.toPixel({0.0, browY}).y), 1, photo.rows));
    // For a person to look at: the photo's outline (cyan), the avatar's (red), the brows' height (green).
    cv::Mat drawn = (side ? o.side : o.front).clone();
    for (const auto& [mask, colour] : {std::pair{photo, cv::Scalar(255, 255, 0)}, std::pair{avatar, cv::Scalar(0, 0, 255)}}) {
        std::vector<std::vector<cv::Point>> outline;
        cv::findContours(mask.clone(), outline, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
        cv::drawContours(drawn, outline, -1, colour, 2, cv::LINE_AA);
    }
    cv::line(drawn, {0, above.height}, {drawn.cols, above.height}, cv::Scalar(0, 255, 0), 1);
    cv::imwrite(overlay.string(), drawn);
    const double both = cv::countNonZero(avatar(above) & photo(above));
    const double either = cv::countNonZero(avatar(above) | photo(above));
    return both / std::max(1.0, either);
}

// How far the hair part's vertices stand out of the photos' outlines at most, in millimetres, past what the head
// under them does (the head fit leaves the crown a few millimetres out of the outline now and then; the hair lies
// on it there).
double hairOutOfOutlinesMm(const FitOutcome& o) {
    const Mesh* head = nullptr;
    const Mesh* hair = nullptr;
    for (const auto& part : o.parts) {
        if (part.name == "head") head = &part.mesh;
        if (part.name == "hair") hair = &part.mesh;
    }
    if (!head || !hair) return 0.0;
    double most = 0.0;
    for (const bool side : {false, true}) {
        const PhotoFrame& frame = side ? o.fit.side : o.fit.front;
        cv::Mat off;
        cv::distanceTransform((side ? o.sideMask : o.frontMask) == 0, off, cv::DIST_L2, cv::DIST_MASK_PRECISE);
        const auto outMm = [&](const glm::dvec3& p) {
            const cv::Point2d px = frame.toPixel(side ? glm::dvec2(p.z, p.y) : glm::dvec2(p.x, p.y));
            const cv::Point at(cvRound(px.x), cvRound(px.y));
            return cv::Rect(0, 0, off.cols, off.rows).contains(at) ? off.at<float>(at) * frame.mmPerPixel : 0.0;
        };
        for (const glm::dvec3& p : hair->positions) {
            const double out = outMm(p);
            if (out <= most) continue;
            const glm::dvec3* nearest = &head->positions.front();
            for (const glm::dvec3& q : head->positions)
                if (glm::distance(p, q) < glm::distance(p, *nearest)) nearest = &q;
            most = std::max(most, out - outMm(*nearest));
        }
    }
    return most;
}

}  // namespace

// Where each side photo shows the ear (the auricle's box, photo pixels, read off the photos by eye), or that hair
// hides it. Partly hidden: the locator may not find it, but what it finds must be the ear.
struct EarInPhoto {
    enum Shows { Clearly, Partly, Hidden } shows;
    cv::Rect2d box;
};
const std::map<std::string, EarInPhoto>& earsInPhotos() {
    static const std::map<std::string, EarInPhoto> ears{
        {"001_Img_13.jpg", {EarInPhoto::Clearly, {545, 342, 67, 83}}}, {"001_Img_53.jpg", {EarInPhoto::Clearly, {335, 350, 65, 82}}},
        {"002_Img_13.jpg", {EarInPhoto::Clearly, {515, 325, 95, 115}}}, {"002_Img_53.jpg", {EarInPhoto::Clearly, {325, 315, 95, 110}}},
        {"003_Img_13.jpg", {EarInPhoto::Clearly, {540, 285, 70, 115}}}, {"003_Img_53.jpg", {EarInPhoto::Clearly, {275, 260, 75, 120}}},
        {"004_Img_13.jpg", {EarInPhoto::Partly, {520, 345, 65, 85}}},   {"004_Img_53.jpg", {EarInPhoto::Clearly, {315, 315, 75, 95}}},
        {"005_Img_13.jpg", {EarInPhoto::Clearly, {490, 230, 65, 110}}}, {"005_Img_53.jpg", {EarInPhoto::Clearly, {315, 230, 65, 105}}},
        {"006_Img_13.jpg", {EarInPhoto::Clearly, {525, 340, 60, 100}}}, {"006_Img_53.jpg", {EarInPhoto::Clearly, {310, 330, 70, 95}}},
        {"007_Img_13.jpg", {EarInPhoto::Hidden, {}}},                    {"007_Img_53.jpg", {EarInPhoto::Partly, {335, 290, 30, 80}}},
        {"008_Img_13.jpg", {EarInPhoto::Clearly, {500, 320, 65, 95}}},  {"008_Img_53.jpg", {EarInPhoto::Clearly, {310, 300, 65, 75}}},
    };
    return ears;
}

// Where each side photo shows the near eye (the middle of its lashes, iris and lids, photo pixels, read off the
// photos by eye), or none where hair hides it (007's left profile).
const std::map<std::string, std::optional<cv::Point2d>>& eyesInPhotos() {
    static const std::map<std::string, std::optional<cv::Point2d>> eyes{
        {"001_Img_13.jpg", cv::Point2d(435, 325)}, {"001_Img_53.jpg", cv::Point2d(490, 307)},
        {"002_Img_13.jpg", cv::Point2d(410, 296)}, {"002_Img_53.jpg", cv::Point2d(515, 290)},
        {"003_Img_13.jpg", cv::Point2d(423, 287)}, {"003_Img_53.jpg", cv::Point2d(474, 277)},
        {"004_Img_13.jpg", cv::Point2d(427, 309)}, {"004_Img_53.jpg", cv::Point2d(487, 315)},
        {"005_Img_13.jpg", cv::Point2d(412, 238)}, {"005_Img_53.jpg", cv::Point2d(484, 233)},
        {"006_Img_13.jpg", cv::Point2d(432, 325)}, {"006_Img_53.jpg", cv::Point2d(472, 314)},
        {"007_Img_13.jpg", std::nullopt},          {"007_Img_53.jpg", cv::Point2d(492, 275)},
        {"008_Img_13.jpg", cv::Point2d(410, 312)}, {"008_Img_53.jpg", cv::Point2d(495, 316)},
    };
    return eyes;
}

class FrmdbFit : public ::testing::TestWithParam<std::tuple<int, const char*>> {};

TEST_P(FrmdbFit, FitsWithoutErrorAndWritesOverlays) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    if (findMakeHumanBaseHead().empty()) GTEST_SKIP() << "the MakeHuman base head was not built";
    char person[8];
    std::snprintf(person, sizeof person, "%03d", std::get<0>(GetParam()));
    const fs::path dir = test::sharedData() / "frmdb" / person;
    const FitPhotoFiles inputs{dir / "Img_33.jpg", dir / std::get<1>(GetParam()), {}};
    const FitOutcome outcome = pipeline().fit(inputs);
    const fs::path out = test::scratchDir(std::string("frmdb_") + person + "_" + std::get<1>(GetParam())) / "session";
    writeSessionFolder(outcome, {inputs}, out, renderer());
    std::printf("%s %s: overlays and previews in %s (%zu warnings)\n", person, std::get<1>(GetParam()), out.c_str(),
                outcome.warnings.size());
    EXPECT_TRUE(fs::exists(out / "front_overlay.jpg"));
    EXPECT_TRUE(fs::exists(out / "side_overlay.jpg"));
    // The fitted head is a plausible adult head: 19-30 cm from the top (hair included) to the chin.
    const Mesh& mesh = outcome.fit.mesh;
    glm::dvec3 lo, hi;
    mesh.bounds(lo, hi);
    EXPECT_GT(hi.x - lo.x, 120.0);
    EXPECT_LT(hi.x - lo.x, 260.0);
    EXPECT_EQ(outcome.sideNoseImageRight, std::string(std::get<1>(GetParam())) == "Img_53.jpg");
    // The warp turned no triangle over against the modifier-fitted head (folds.py's count, here 0).
    const auto folds = foldedTriangles(outcome.fit.scaledBase, mesh);
    double sum = 0.0;
    for (const auto& r : outcome.fit.residuals) sum += r.errorMm * r.errorMm;
    std::printf("%s %s: modifiers %.1f -> %.1f mm RMS on the targets, %zu folds smoothed out, residual RMS %.2f mm\n",
                person, std::get<1>(GetParam()), outcome.fit.modifierRmsMm.first, outcome.fit.modifierRmsMm.second,
                outcome.fit.foldsRemoved, std::sqrt(sum / static_cast<double>(std::max<std::size_t>(outcome.fit.residuals.size(), 1))));
    EXPECT_TRUE(folds.empty()) << folds.size() << " triangles turned over";
    // The ear is found where the side photo shows it, and the fitted head's ears were moved there (the base head's
    // ear sat where proportions put it: the side photo's ear was painted on the scalp behind and below it).
    {
        const EarInPhoto& ear = earsInPhotos().at(std::string(person) + "_" + std::get<1>(GetParam()));
        const EarSpot& spot = outcome.sideEar;
        std::printf("%s %s: ear %s at %.0f, %.0f (correlation %.2f); the head's ears moved %.1f mm forward, %.1f mm up "
                    "(%.1f, %.1f wanted; %.1f, %.1f left to the texture)\n",
                    person, std::get<1>(GetParam()), spot.found ? "found" : "not found", spot.centre.x, spot.centre.y,
                    spot.score, outcome.fit.earShiftMm.x, outcome.fit.earShiftMm.y, outcome.fit.earOffsetMm.x,
                    outcome.fit.earOffsetMm.y, outcome.fit.earLeftMm.x, outcome.fit.earLeftMm.y);
        if (ear.shows == EarInPhoto::Clearly) {
            EXPECT_TRUE(spot.found) << "the ear the photo shows was not found";
        }
        if (ear.shows == EarInPhoto::Hidden) {
            EXPECT_FALSE(spot.found) << "an ear was found under the hair";
        }
        if (spot.found) {
            EXPECT_TRUE(ear.box.contains(spot.centre)) << "the ear found at " << spot.centre << " is not in " << ear.box;
            EXPECT_TRUE(outcome.fit.earsPlaced);
            // Moved by what was wanted, within the sliders' ranges (MakeHuman's ear translations: 10 mm back,
            // 12.5 forward, 20 up or down at the base head's size).
            for (int c = 0; c < 2; ++c) {
                EXPECT_LE(std::abs(outcome.fit.earShiftMm[c]), std::abs(outcome.fit.earOffsetMm[c]) + 1e-9);
                EXPECT_GE(outcome.fit.earShiftMm[c] * outcome.fit.earOffsetMm[c], 0.0);
            }
        } else {
            EXPECT_FALSE(outcome.fit.earsPlaced);
        }
    }
    // The near eye is found where the side photo shows it (within 20 px, 13 mm, along and 16 px up or down: the
    // darkest spot, the lashes and the iris, lies off the eye's middle by up to 14 px), and the texture reads the
    // side photo shifted by its offset from the head's eye (measured: 002-007's right profiles, Img_53, 10-23 mm
    // further back than the head's, turned short of a profile; the left ones, and 001's and 008's right, within 4 mm,
    // but 001's left 12).
    {
        const std::optional<cv::Point2d>& eye = eyesInPhotos().at(std::string(person) + "_" + std::get<1>(GetParam()));
        const SideEyeSpot& spot = outcome.sideEye;
        std::printf("%s %s: eye %s at %.0f, %.0f (contrast %.0f); %.1f mm forward, %.1f mm up of the head's\n", person,
                    std::get<1>(GetParam()), spot.found ? "found" : "not found", spot.centre.x, spot.centre.y,
                    spot.contrast, outcome.fit.eyeLeftMm.x, outcome.fit.eyeLeftMm.y);
        if (eye) {
            EXPECT_TRUE(spot.found) << "the eye the photo shows was not found";
            EXPECT_LE(std::abs(spot.centre.x - eye->x), 20.0) << spot.centre << " against " << *eye;
            EXPECT_LE(std::abs(spot.centre.y - eye->y), 16.0) << spot.centre << " against " << *eye;
            EXPECT_TRUE(outcome.fit.sideEyeFound);
        } else {
            EXPECT_FALSE(spot.found) << "an eye was found under the hair at " << spot.centre;
            EXPECT_FALSE(outcome.fit.sideEyeFound);
        }
    }
    // The glb reads back with the same head (its first part: the fitted head without the eyeballs the eyes replace).
    const Mesh back = readGlbMesh(out / "avatar.glb");
    ASSERT_FALSE(outcome.parts.empty());
    EXPECT_EQ(back.positions.size(), outcome.parts.front().mesh.positions.size());
    // The face the photo shows is not hidden by the hair in the front view: its eyes, nose and mouth (ibug 27-67)
    // (bob02's fringe fell over 008's eye before the hair kept the face clear).
    for (const auto& part : outcome.parts) {
        if (part.name != "hair") continue;
        std::vector<std::string> covered;
        for (int k = 27; k < 68; ++k) {
            const glm::dvec3& p = mesh.positions[pipeline().baseHead().frontFeatures.at(landmarkName(k))];
            if (part.mesh.frontZ(p.x, p.y) > p.z) covered.push_back(landmarkName(k));  // NaN: no hair there
        }
        EXPECT_TRUE(covered.empty()) << "hair in front of " << ::testing::PrintToString(covered);
        // Where the photo shows the forehead, a bob's fringe leaves it clear (008's parted curls: bob02's fringe down
        // to his brows made a helmet of them): the forehead's middle from the brows to 10 mm under the hairline the
        // photo shows is not behind hair.
        if (outcome.hair.style == HairStyle::Bob) {
            std::printf("%s %s: the photo shows %.1f mm of forehead over the brows\n", person, std::get<1>(GetParam()),
                        outcome.foreheadShownMm);
            const glm::dvec3& left = mesh.positions[pipeline().baseHead().frontFeatures.at(landmarkName(20))];
            const glm::dvec3& right = mesh.positions[pipeline().baseHead().frontFeatures.at(landmarkName(23))];
            std::vector<double> hidden;
            for (double up = 2.0; up < outcome.foreheadShownMm - 10.0; up += 2.0)
                for (const double t : {0.0, 0.5, 1.0}) {
                    const glm::dvec3 p = left + t * (right - left) + glm::dvec3(0.0, up, 0.0);
                    const double skin = mesh.frontZ(p.x, p.y), hair = part.mesh.frontZ(p.x, p.y);
                    if (hair > skin) hidden.push_back(up);  // NaN: no hair there
                }
            EXPECT_TRUE(hidden.empty()) << "the forehead behind hair at " << ::testing::PrintToString(hidden) << " mm over the brows";
            // 008's curls hang to his collar behind the head in both profiles (read off the photos by eye), 20 mm and
            // more under bob02's ends, which left them painted on his neck under the bob: the bob now hangs as low as
            // the side photo's hair, behind the head.
            const HairLength& length = outcome.hairLength;
            double lowestBehind = std::numeric_limits<double>::infinity();
            for (const glm::dvec3& q : part.mesh.positions)
                if (q.z < HairLengthFit{}.behindZ) lowestBehind = std::min(lowestBehind, q.y);
            std::printf("%s %s: the photo's hair behind the head down to %.1f mm, bob02's to %.1f: length x %.2f, now down to %.1f\n",
                        person, std::get<1>(GetParam()), length.photoBottom, length.avatarBottom, length.factor, lowestBehind);
            EXPECT_TRUE(length.measured);
            EXPECT_LT(length.photoBottom, length.avatarBottom - 15.0);
            EXPECT_NEAR(lowestBehind, length.photoBottom, 1.0);
        }
        // Seen from either side, the head shows nowhere through long hair or a bob: the fitted head's ears stood out
        // through long01 and were drawn as an arc on the hair (005, 006, 007) until tuckEarsUnderHair. Short hair and
        // a ponytail leave the ears out (as 002's, 003's and 004's photos show them), so the ears stand out there.
        constexpr double kThroughHairMm = 5.0;
        const double jawZ = jawTopDepth(pipeline().baseHead(), mesh);
        int through = 0, outside = 0, underHair = 0;
        for (const double side : {1.0, -1.0}) {
            Mesh fromSide = part.mesh;  // looking along -x (side +1) or +x (side -1): depth is side * x
            for (glm::dvec3& q : fromSide.positions) q = {q.z, q.y, side * q.x};
            for (const glm::dvec3& p : outcome.parts.front().mesh.positions) {
                if (side * p.x <= 0.0 || std::abs(p.y) > 45.0 || p.z < -35.0 || p.z >= jawZ) continue;
                const double hairDepth = fromSide.frontZ(p.z, p.y);
                if (std::isnan(hairDepth)) continue;
                ++underHair;
                // Through the hair's outer layer: standing out of hair that lies under it by less than an ear stands
                // out (hair deeper under the head is hidden; where the hair went behind the face, the ear is bare).
                const double standsOut = side * p.x - hairDepth;
                if (standsOut > 0.0) ++outside;
                if (standsOut > 0.0 && standsOut < kThroughHairMm) ++through;
            }
        }
        std::printf("%s %s: %d of the %d head vertices beside the ears under hair show through it from the side\n", person,
                    std::get<1>(GetParam()), through, underHair);
        // The ears go under the hair, the head's side round them stays: a head vertex moves by more than 2 mm only
        // within the ear (30 mm along the head and 60 mm up and down round its middle). bob02's layers under the skin
        // beside 008's ears had the cheek in front of them pressed in by up to 25 mm, a dent down it.
        std::map<std::pair<double, double>, double> fittedX;  // the tuck moves vertices sideways only
        for (const glm::dvec3& q : mesh.positions) fittedX[{q.y, q.z}] = q.x;
        glm::dvec3 ear(0.0);  // the right ear's middle (its vertices' mean); the left mirrors it
        {
            const BaseHead& base = pipeline().baseHead();
            ASSERT_TRUE(base.modifiers);
            const std::vector<std::uint32_t> earVertices = rigidlyMovedVertices(*base.modifiers, kRightEarTranslation);
            ASSERT_FALSE(earVertices.empty());
            for (const auto v : earVertices) ear += mesh.positions[v] / static_cast<double>(earVertices.size());
        }
        double tuckedEar = 0.0, tuckedSide = 0.0;
        for (const glm::dvec3& p : outcome.parts.front().mesh.positions) {
            const auto it = fittedX.find({p.y, p.z});
            if (it == fittedX.end()) continue;
            const double moved = std::abs(it->second) - std::abs(p.x);
            const bool inEar = std::abs(p.z - ear.z) < 15.0 && std::abs(p.y - ear.y) < 30.0;
            (inEar ? tuckedEar : tuckedSide) = std::max(inEar ? tuckedEar : tuckedSide, moved);
        }
        // Where the side photo shows the ear bare with the hair behind it (tuckHairBehindTheFace; by eye: 001's and
        // 008's ears in both profiles), the avatar's ear is bare from the side too: no hair outside it or hair only
        // deep under it. Before, long01 and bob02 hid every long-haired or bobbed visitor's (0 of 337 vertices);
        // now 008 222 and 269, 001 133 and 38 (in Img_53 her hair's edge lies over the ear's back).
        int bareEar = 0, earSeen = 0;
        {
            const BaseHead& base = pipeline().baseHead();
            Mesh fromSide = part.mesh;  // looking along -x, at the right ear (x > 0 on the base head's right side)
            const double side = ear.x > 0.0 ? 1.0 : -1.0;
            for (glm::dvec3& q : fromSide.positions) q = {q.z, q.y, side * q.x};
            for (const auto v : rigidlyMovedVertices(*base.modifiers, kRightEarTranslation)) {
                const glm::dvec3& p = outcome.parts.front().mesh.positions[v];
                const double hairDepth = fromSide.frontZ(p.z, p.y);
                ++earSeen;
                if (std::isnan(hairDepth) || side * p.x - hairDepth > kThroughHairMm) ++bareEar;
            }
        }
        std::printf("%s %s: %d of the right ear's %d vertices bare from the side (%d hair vertices tucked behind the face)\n",
                    person, std::get<1>(GetParam()), bareEar, earSeen, outcome.hairTuckedVertices);
        if (std::string(person) == "008") {
            EXPECT_GT(bareEar, earSeen / 2);
        }
        if (std::string(person) == "001") {
            EXPECT_GT(bareEar, earSeen / 10);
        }
        std::printf("%s %s: head vertices tucked under the hair by up to %.1f mm in the ears, %.1f mm elsewhere\n", person,
                    std::get<1>(GetParam()), tuckedEar, tuckedSide);
        EXPECT_LT(tuckedSide, 2.0);
        // (003's short hair, trimmed to his fade, leaves no hair beside his ears at all.)
        // Where hair went behind the face, the bare ear meets the tucked hair's front edge: a few of its vertices lie
        // just outside the hair there (005 6 and 3 of 222 and 90, 008 15 and 10 of about 790, 006's right profile 47
        // of 386: by eye an ear in front of the hair, as in her photo).
        if (hairCoversEars(outcome.hair.style)) {
            if (outcome.hairTuckedVertices == 0) {
                EXPECT_EQ(through, 0);
            } else {
                EXPECT_LT(through, underHair / 7);
            }
        } else {
            EXPECT_TRUE(underHair == 0 || outside > 0) << "the ears vanished under " << toString(outcome.hair.style) << " hair";
        }
    }
    // The avatar's outline above the brows is the photos': with short hair the head fit follows the outline, so the
    // hair part must add no volume (short02 over the fitted heads of 002 and 003: 0.74-0.81; short04 0.91-0.95).
    // Big hair follows the photos' outlines beside and behind the head (fitHairToSilhouettes: 0.77-0.89, the proxies
    // as they come 0.67-0.84; 008's curls are fuller than the bob, 005's hair falls to one side).
    const double frontAgreement = silhouetteAgreementAboveBrows(outcome, false, out.parent_path() / "silhouette_front.jpg");
    const double sideAgreement = silhouetteAgreementAboveBrows(outcome, true, out.parent_path() / "silhouette_side.jpg");
    std::printf("%s %s: %s hair; the avatar's silhouette over the photo's above the brows (IoU): front %.3f, side %.3f\n",
                person, std::get<1>(GetParam()), toString(outcome.hair.style), frontAgreement, sideAgreement);
    const double floor = outcome.hair.style == HairStyle::Short ? 0.85 : 0.75;
    EXPECT_GT(frontAgreement, floor);
    EXPECT_GT(sideAgreement, floor);
    // Short hair stays in the outlines (pullShortHairIntoOutlines; without it short04 stood 7.1-11.0 mm further out
    // of 002's and 003's photos than their heads, at the back of the head, and one card of 003's hung down to his
    // nape; with it 2.0-3.4: the margin, the layers' band and the pull's first-order reading of the outline).
    const double hairOut = hairOutOfOutlinesMm(outcome);
    std::printf("%s %s: the hair stands at most %.1f mm further out of the photos' outlines than the head under it\n",
                person, std::get<1>(GetParam()), hairOut);
    if (outcome.hair.style == HairStyle::Short) {
        EXPECT_LT(hairOut, 4.0);
    }
    std::printf("%s %s: %d texels of the photo's hair beside the face repainted with skin\n", person,
                std::get<1>(GetParam()), outcome.skinOverHairTexels);
    if (!hairCoversEars(outcome.hair.style)) {
        EXPECT_EQ(outcome.skinOverHairTexels, 0);
    }
    // 002 wears a yellow hood round his neck in both profiles: it was painted on the back of his neck.
    std::printf("%s %s: %d texels of clothes on the neck repainted with skin\n", person, std::get<1>(GetParam()),
                outcome.skinOverClothesTexels);
    if (std::string(person) == "002") {
        EXPECT_GT(outcome.skinOverClothesTexels, 5000);
    }
    std::printf("%s %s: parts", person, std::get<1>(GetParam()));
    for (const auto& part : outcome.parts) std::printf(" %s", part.name.c_str());
    for (const auto& [name, c] : outcome.partColours) std::printf("; %s (%.0f %.0f %.0f)", name.c_str(), c[0], c[1], c[2]);
    std::printf("\n");
}

INSTANTIATE_TEST_SUITE_P(AllPeople, FrmdbFit,
                         ::testing::Combine(::testing::Range(1, 9), ::testing::Values("Img_13.jpg", "Img_53.jpg")),
                         [](const ::testing::TestParamInfo<std::tuple<int, const char*>>& p) {
                             return "person" + std::to_string(std::get<0>(p.param)) +
                                    (std::string(std::get<1>(p.param)) == "Img_13.jpg" ? "_nose_left" : "_nose_right");
                         });
