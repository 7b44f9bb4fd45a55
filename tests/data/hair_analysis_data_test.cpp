// The hair style, colour and beard read from the 16 FRMDB pairs (8 people, both profiles) against what a person
// sees in the photos (the table below: judged by eye from Img_33, Img_13 and Img_53); the overlays are written
// under build/release/tests/work/hair_frmdb/ for a person to check.
#include "test_paths.h"

#include "common/image_io.h"
#include "fit/face/hair_analysis.h"
#include "fit/fit_pipeline.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <cstdio>

namespace fs = std::filesystem;
using namespace avatarbooth;

namespace {

// Judged from the photos: 001 long straight brown hair over the shoulders; 002 short dark hair; 003 short (an
// undercut), dark blond, light stubble on chin and jaw (too light to call either way: not asserted); 004 curly red
// brown hair tied back in a low knot at the nape (the closest style: a ponytail); 005, 006, 007 long, past the
// shoulders; 008 a man's chin-length wavy bob. No one has a full beard or a moustache that reads as one.
struct Judged {
    int person;
    HairStyle style;
    int beard;  // 1 yes, 0 no, -1 not asserted
};
constexpr Judged kJudged[] = {
    {1, HairStyle::Long, 0},  {2, HairStyle::Short, 0},    {3, HairStyle::Short, -1}, {4, HairStyle::Ponytail, 0},
    {5, HairStyle::Long, 0},  {6, HairStyle::Long, 0},     {7, HairStyle::Long, 0},   {8, HairStyle::Bob, -1},
};

const FitPipeline& hairPipeline() {
    static const FitPipeline p{FitSettings{}};
    return p;
}

struct Result {
    HairEstimate estimate;
    HairStyle expected;
};

Result analysePair(int person, const char* sideFile) {
    char id[8];
    std::snprintf(id, sizeof id, "%03d", person);
    const fs::path dir = test::sharedData() / "frmdb" / id;
    HairPhotos photos;
    photos.front = readPhoto(dir / "Img_33.jpg");
    photos.side = readPhoto(dir / sideFile);
    const FrontAnalysis front = hairPipeline().analyseFront(photos.front, cv::Mat());
    photos.frontMask = front.mask;
    photos.frontPoints = front.landmarks.points;
    const SideAnalysis side = analyseSidePhoto(photos.side);
    photos.sideMask = side.mask;
    photos.sideNoseImageRight = side.noseImageRight;
    for (const auto& q : side.landmarks) photos.sidePoints[q.name] = q.px;
    Result r{estimateHair(photos), kJudged[person - 1].style};
    const fs::path out = fs::path(AVATARBOOTH_TEST_WORK_DIR) / "hair_frmdb";
    fs::create_directories(out);
    const auto [f, s] = drawHairOverlay(photos, r.estimate);
    cv::imwrite((out / (std::string(id) + "_front.jpg")).string(), f);
    cv::imwrite((out / (std::string(id) + "_" + sideFile)).string(), s);
    return r;
}

}  // namespace

TEST(HairAnalysisFrmdb, StyleAndBeardAsJudgedByEye) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    int right = 0, total = 0;
    for (const Judged& j : kJudged)
        for (const char* side : {"Img_13.jpg", "Img_53.jpg"}) {
            const Result r = analysePair(j.person, side);
            const HairEvidence& e = r.estimate.evidence;
            std::printf("%03d %s: %-8s (judged %-8s) crown %.2f (%4.1f; forehead %4.1f hue %4.1f sat %.2f hairline %.2f) beside %.2f below %.2f clothes %.2f behind %.2f back %.2f | chin %.1f lip %.1f "
                        "jaw %.1f%s%s | colour BGR %.0f %.0f %.0f\n",
                        j.person, side, toString(r.estimate.style), toString(r.expected), e.crown, e.hairFromSkin, e.foreheadFromSkin, e.crownHueShift,
                        e.crownSaturation, e.hairline, e.besideFace, e.belowChin, e.clothesAsHair,
                        e.behindHead, e.downTheBack, e.chinDarkening, e.upperLipDarkening, e.jawDarkening,
                        r.estimate.beard ? " beard" : "", r.estimate.moustache ? " moustache" : "", r.estimate.colour[0],
                        r.estimate.colour[1], r.estimate.colour[2]);
            ++total;
            right += r.estimate.style == r.expected;
            EXPECT_NE(r.estimate.style, HairStyle::None) << j.person << " " << side << ": everyone here has hair";
            if (j.beard >= 0) {
                EXPECT_EQ(r.estimate.beard, j.beard == 1) << j.person << " " << side;
            }
            // Everyone's hair here is dark to mid brown: darker than the skin, warmer (R >= B) than the backdrop.
            EXPECT_LT(r.estimate.colour[0] + r.estimate.colour[1] + r.estimate.colour[2],
                      r.estimate.skinColour[0] + r.estimate.skinColour[1] + r.estimate.skinColour[2])
                << j.person << " " << side;
            EXPECT_GE(r.estimate.colour[2], r.estimate.colour[0]) << j.person << " " << side;
        }
    std::printf("hair style as judged: %d of %d pairs\n", right, total);
    // Measured 2026-12-04: 16 of 16 (14 until the low knot of 004, which read as a bob for the hair beside its
    // jaw, was told from one by the side's hair tied back: HairOptions::tiedBackBeside).
    EXPECT_EQ(right, 16) << "of 16";
}
