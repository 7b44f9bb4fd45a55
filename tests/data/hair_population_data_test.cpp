// The hair analysis against synthetic MakeHuman people whose hair and beard are known (sim/makehuman_visitor.h): a
// seeded set, each photographed front and side, analysed as the booth does (dlib's landmarks, the silhouettes, the
// profile points) and the estimate compared with the truth. Prints the confusion table; asserts what held with
// margin when it was written. Needs the product's base head; skips when it is absent.
#include "test_paths.h"

#include "common/error.h"
#include "fit/face/hair_analysis.h"
#include "fit/face/profile.h"
#include "fit/fit_error.h"
#include "fit/fit_pipeline.h"
#include "fit/parts/hair_part.h"
#include "sim/makehuman_visitor.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

namespace fs = std::filesystem;
using namespace avatarbooth;

namespace {

constexpr unsigned kPeople = 36;

// CIE76 colour difference of two BGR colours (0..255).
double deltaE(const cv::Vec3d& a, const cv::Vec3d& b) {
    cv::Mat m(1, 2, CV_32FC3);
    m.at<cv::Vec3f>(0, 0) = cv::Vec3f(a / 255.0);
    m.at<cv::Vec3f>(0, 1) = cv::Vec3f(b / 255.0);
    cv::cvtColor(m, m, cv::COLOR_BGR2Lab);
    return cv::norm(m.at<cv::Vec3f>(0, 0) - m.at<cv::Vec3f>(0, 1));
}

}  // namespace

namespace {

// withPlate: the silhouettes from a photo of the empty booth as well (the batch and `fit --background`), or from the
// photos alone, as the kiosk analyses them.
void styleColourAndBeardOfKnownPeople(bool withPlate) {
    if (findMakeHumanBaseHead().empty()) GTEST_SKIP() << "the MakeHuman base head was not built";
    const auto base = productBaseHead();
    const FitPipeline pipeline{FitSettings{}, *base};
    MeshRenderer renderer;
    std::map<std::string, std::map<std::string, int>> confusion;  // truth -> estimate -> count
    int styleRight = 0, beardRight = 0, moustacheRight = 0, withHair = 0, refused = 0, bald = 0, baldRight = 0;
    int longHair = 0, longRight = 0, longWrongly = 0;
    int tipsNear = 0, nasionsNear = 0, refusedWrongWords = 0;
    std::vector<double> colourErrors;
    const fs::path out = test::scratchDir(withPlate ? "hair_population" : "hair_population_no_plate");
    for (unsigned seed = 1; seed <= kPeople; ++seed) {
        MakeHumanVisitorOptions options;
        options.seed = seed;
        options.sideNoseImageRight = seed % 2 == 0;
        options.hairProxies = true;
        const MakeHumanVisitor v = makeMakeHumanVisitor(*base, renderer, options);
        const cv::Mat plate = withPlate ? v.photos.background : cv::Mat();
        const MakeHumanPerson& p = v.person;
        HairPhotos photos;
        try {
        photos.front = v.photos.front;
        photos.side = v.photos.side;
        const FrontAnalysis front = pipeline.analyseFront(v.photos.front, plate);
        photos.frontMask = front.mask;
        photos.frontPoints = front.landmarks.points;
        SideOptions sideOptions;
        sideOptions.landmarkDetector = &pipeline.detector();  // as the pipeline analyses it
        const SideAnalysis side = analyseSidePhoto(v.photos.side, plate, sideOptions);
        photos.sideMask = side.mask;
        photos.sideNoseImageRight = side.noseImageRight;
        for (const auto& q : side.landmarks) photos.sidePoints[q.name] = q.px;
        // Where the profile analysis put the nose tip and the nasion, against the truth (pixels, 0.6 mm each).
        const double tipPx = cv::norm(photos.sidePoints.at("nose_tip") - v.photos.sideLandmarks.at("nose_tip"));
        const double nasionPx = cv::norm(photos.sidePoints.at("nasion") - v.photos.sideLandmarks.at("nasion"));
        tipsNear += tipPx <= 6.0;
        nasionsNear += nasionPx <= 10.0;
        std::printf("%3u profile: nose tip %.1f px from the true one, nasion %.1f px\n", seed, tipPx, nasionPx);
        } catch (const BoothError& err) {
            // The booth refuses such photos; the hair analysis never sees them.
            ++refused;
            // Every side photo here is a profile: hair over the face is the one reason to refuse it, and the
            // visitor is told so (not "a front view", not "turn more").
            const auto* fit = dynamic_cast<const FitError*>(&err);
            refusedWrongWords += !fit || fit->fault() != FitFault::FaceHidden;
            cv::imwrite((out / ("seed" + std::to_string(seed) + "_refused_side.jpg")).string(), v.photos.side);
            std::printf("%3u %-6s %-9s %-20s refused: %s\n", seed, p.sex.c_str(), p.hairStyle.c_str(), p.hair.c_str(), err.what());
            continue;
        }
        const HairEstimate e = estimateHair(photos);
        const auto [f, s] = drawHairOverlay(photos, e);
        cv::imwrite((out / ("seed" + std::to_string(seed) + "_front.jpg")).string(), f);
        cv::imwrite((out / ("seed" + std::to_string(seed) + "_side.jpg")).string(), s);

        ++confusion[p.hairStyle][toString(e.style)];
        styleRight += p.hairStyle == toString(e.style);
        if (p.hairStyle == "none") ++bald, baldRight += e.style == HairStyle::None;
        if (p.hairStyle == "long") ++longHair, longRight += e.style == HairStyle::Long;
        else longWrongly += e.style == HairStyle::Long;
        const bool beard = p.beard == "full", moustache = p.beard != "none";
        beardRight += e.beard == beard;
        moustacheRight += e.moustache == moustache;
        double dE = 0.0;
        const cv::Vec3d painted = hairPaint(e.colour);
        if (p.hairStyle != "none" && e.style != HairStyle::None) {
            ++withHair;
            dE = deltaE(painted, p.hairColour);
            colourErrors.push_back(dE);
        }
        const HairEvidence& x = e.evidence;
        std::printf("%3u %-6s %-9s %-20s -> %-8s | crown %.2f (%4.1f; forehead %4.1f hue %4.1f sat %.2f hairline %.2f) beside %.2f below %.2f clothes %.2f behind %.2f back %.2f | beard %-9s chin %5.1f "
                    "lip %5.1f jaw %5.1f -> %s%s | dE %.1f (BGR %3.0f %3.0f %3.0f for %3.0f %3.0f %3.0f)\n",
                    seed, p.sex.c_str(), p.hairStyle.c_str(), p.hair.c_str(), toString(e.style), x.crown, x.hairFromSkin, x.foreheadFromSkin, x.crownHueShift,
                    x.crownSaturation, x.hairline, x.besideFace,
                    x.belowChin, x.clothesAsHair, x.behindHead, x.downTheBack, p.beard.c_str(), x.chinDarkening, x.upperLipDarkening,
                    x.jawDarkening, e.beard ? "beard" : "-", e.moustache ? "+moustache" : "", dE, painted[0], painted[1], painted[2],
                    p.hairColour[0], p.hairColour[1], p.hairColour[2]);
    }
    std::printf("\nconfusion (rows: truth, columns: estimate)\n%-9s", "");
    for (const HairStyle s : kHairStyles) std::printf(" %8s", toString(s));
    std::printf("\n");
    for (const auto& [truth, row] : confusion) {
        std::printf("%-9s", truth.c_str());
        for (const HairStyle s : kHairStyles) {
            const auto it = row.find(toString(s));
            std::printf(" %8d", it == row.end() ? 0 : it->second);
        }
        std::printf("\n");
    }
    std::sort(colourErrors.begin(), colourErrors.end());
    const double medianDe = colourErrors.empty() ? 0.0 : colourErrors[colourErrors.size() / 2];
    const double worstDe = colourErrors.empty() ? 0.0 : colourErrors.back();
    std::printf("refused by the photo analysis: %d\n", refused);
    std::printf("style right %d of %u; beard right %d, moustache right %d of %u; hair colour dE median %.1f, worst %.1f over %d "
                "people with hair\n",
                styleRight, kPeople, beardRight, moustacheRight, kPeople, medianDe, worstDe,
                withHair);
    // With MakeHuman's hair proxies in the photos: a fringe or a quiff standing as far forward as the nose was taken
    // for it, and 5 clean profiles were refused (3, 7, 27, 33, 35: "nasion 0.45 V above the nose tip", "no nose-like
    // forward bulge"); the profile analysis now tries the next bulge (fitProfile). Still refused: the three bobs whose
    // hair hides the profile (9, 20, 34), told so (they were told "a front view"). The profile's points are where the
    // truth has them: every nose tip within 6 px (3.6 mm) but one (36, whose full lips stand 2 px further forward than
    // her nose), every nasion within 10 px but one (29, whose bob's fringe covers the forehead down to the brows: the
    // nasion is taken under it), as before the fringes were told from noses. The rest is what held when this was
    // written.
    const int analysed = static_cast<int>(kPeople) - refused;
    std::printf("profile: of %d, %d nose tips within 6 px of the truth, %d nasions within 10 px\n", analysed, tipsNear,
                nasionsNear);
    // Without the plate (the kiosk), clothes as cold as the blue backdrop are left out of the silhouette (see
    // segmentPerson), and the outline ends at the collar. Until the profile sought the chin and throat above the
    // collar (fitProfile), two long-haired visitors' profiles (18, 28) were refused ("no chin and throat below the
    // nose": the outline's front runs on along the collar to the hair's ends), and on four more the lips were taken
    // for the nose (17, 19, 26, 36: 37-47 px off); now as with the plate (36's full lips stand further forward than
    // her nose either way).
    EXPECT_LE(refused, 3);
    EXPECT_EQ(refusedWrongWords, 0) << "a profile refused for another reason than hair hiding the face";
    EXPECT_GE(tipsNear, analysed - 1);
    EXPECT_GE(nasionsNear, analysed - 1);
    // A bald crown's shading is no hair (HairOptions::shadeHueShift): all 5 bald or balding people analysed. Long
    // hair reads long whatever its colour: the hair's colour is read from the temples too, not from the crown's top
    // light alone (blond 22 and 28 read short before). Every one of the 33 analysed styles right when this was
    // written; 20 of 28 before the forehead's comparison and the hairline, 24 before the temples and the ponytail
    // windows under the head's back, 27 before clothes of the hair's colour were told from long hair (bob 29 over a
    // brown shirt read long: HairOptions::clothesAsHair), 32 of 33 with the profiles under a fringe.
    EXPECT_EQ(baldRight, bald);
    EXPECT_EQ(longRight, longHair);
    EXPECT_EQ(longWrongly, 0) << "hair read long that is not (clothes of the hair's colour under the neck)";
    EXPECT_GE(styleRight, analysed - 1);
    EXPECT_GE(beardRight, analysed * 9 / 10);
    EXPECT_GE(moustacheRight, analysed * 9 / 10);
    EXPECT_GE(withHair, 18);
    // The colour from the front's crown and temples and the side's crown, painted to show it under the booth's
    // lights (hairPaint), against the painted truth: dE median 1.9, worst 9.4 when this was written (8.7 and 22.1
    // read as the photo shows it, with the texture's tint normalised over all its texels; 10.2 from the front alone).
    EXPECT_LT(medianDe, 3.0);
    EXPECT_LT(worstDe, 12.0);
}

}  // namespace

TEST(HairPopulation, StyleColourAndBeardOfKnownPeople) { styleColourAndBeardOfKnownPeople(true); }

// The kiosk takes no photo of the empty booth: the silhouettes come from the photos' colours alone, the backdrop's
// learnt from the frame's borders. A tall visitor's hair reaching into the top border was learnt as the backdrop's
// colour: seed 3's brown hair was left out of both silhouettes (no hair, the head cut off at the hairline), and two
// more were refused (18 "no face shows", 19 "the head in the side photo is 54% the size"). The same assertions.
TEST(HairPopulation, WithoutTheBackgroundPlateAsTheKioskAnalyses) { styleColourAndBeardOfKnownPeople(false); }

// A bob's length behind the head is read from the side photo (fitHairLengthBehind). The synthetic people who wear a
// bob wear MakeHuman's bob02 on their own heads, as the avatar does on the fitted one: the photo's bob ends where the
// avatar's does, and the length must stay as it came (FRMDB 008's curls, to his collar, lengthen his by a half).
// Fitted without the plate, as the kiosk fits. Of the first 108 seeds, 18 wear a bob and these two are the ones whose
// bob leaves the profile clear and reads as a bob (the others are refused, the hair over the face, or read short or
// bald): 29 (the photo's hair ends 11 mm over the avatar's: the strands' ends fade into the backdrop) and 78 (6 mm).
TEST(HairPopulation, ABobKeepsItsLengthWhereThePhotoShowsItsOwn) {
    if (findMakeHumanBaseHead().empty()) GTEST_SKIP() << "the MakeHuman base head was not built";
    const auto base = productBaseHead();
    const FitPipeline pipeline{FitSettings{}, *base};
    MeshRenderer renderer;
    for (const unsigned seed : {29u, 78u}) {
        MakeHumanVisitorOptions options;
        options.seed = seed;
        options.sideNoseImageRight = seed % 2 == 0;
        options.hairProxies = true;
        const MakeHumanVisitor v = makeMakeHumanVisitor(*base, renderer, options);
        ASSERT_EQ(v.person.hairStyle, "bob") << "seed " << seed << ": the synthetic people have changed";
        const FitOutcome o = pipeline.fit(v.photos.front, v.photos.side, cv::Mat());
        ASSERT_EQ(o.hair.style, HairStyle::Bob) << "seed " << seed;
        const HairLength& l = o.hairLength;
        std::printf("%3u bob: %s, the photo's hair behind the head down to %.1f mm, the avatar's %.1f mm: length x %.3f\n",
                    seed, l.measured ? "measured" : "not measured", l.photoBottom, l.avatarBottom, l.factor);
        ASSERT_TRUE(l.measured) << "seed " << seed;
        EXPECT_LE(l.factor, 1.12) << "seed " << seed;  // (never under 1: only lengthened)
    }
}
