// Side photos as visitors give them (issue 22): MakeHuman visitors (sim/makehuman_visitor.h) photographed from the
// side turned 60-120 degrees from the front, both ways round. 70-110 must fit, with the face's shape error near the
// true profile's; at 60 and 120 each visitor either fits or is told the right way to turn, by the fit and by the side
// guide: "turn more" never at 70-120, "turn a little back" or "we can't see your face" never at 60-70 (at 120 the
// ear's "turn a little back" reaches 2 of the 6, the missing face 2 more, 2 fit; at 60 the face found without a nose
// on the outline 2, the eye, the ear and the face together 3 more, 1 fits). Needs the product's base head;
// skips when it is absent. AVATARBOOTH_TURNED_OUT=DIR keeps the side photos and overlays.
#include "face_shape_error.h"
#include "test_paths.h"

#include "booth/guidance.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "common/image_io.h"
#include "fit/face/profile.h"
#include "fit/fit_error.h"
#include "fit/fit_pipeline.h"
#include "fit/head/makehuman_import.h"
#include "sim/makehuman_visitor.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>
#include <string>

namespace fs = std::filesystem;
using namespace avatarbooth;
using avatarbooth::test::faceRegion;
using avatarbooth::test::faceRms;
using avatarbooth::test::median;

namespace {

constexpr unsigned kPeople = 6;
constexpr int kYaws[] = {60, 70, 80, 90, 100, 110, 120};

}  // namespace

TEST(TurnedProfiles, FitFrom70To110AndSayWhichWayToTurnBeyond) {
    if (findMakeHumanBaseHead().empty())
        GTEST_SKIP() << "the MakeHuman base head is not built (build the target base_head); skipping";
    const auto base = productBaseHead();
    const FitPipeline pipeline(FitSettings{}, *base);
    MeshRenderer renderer;
    PreviewAnalyser analyser(&pipeline.detector(), {});
    const std::vector<bool> face = faceRegion(*base);
    const char* outEnv = std::getenv("AVATARBOOTH_TURNED_OUT");
    const fs::path out = outEnv && *outEnv ? fs::path(outEnv) : fs::path();

    std::map<int, std::vector<double>> rms;
    int turnMoreAt60 = 0, turnBackAt120 = 0, pastAt120 = 0, turnBackWrongly = 0, pastWrongly = 0;
    int fitTurnBackAt120 = 0, fitTurnBackWrongly = 0;
    int rightWayAt60 = 0, rightWayAt120 = 0, guideWrongWay = 0, fitWrongWay = 0, turnMoreWrongly = 0;
    const auto towardsCamera = [](Hint h) { return h == Hint::TurnBack || h == Hint::FaceHidden; };
    const auto towardsCameraFault = [](FitFault f) { return f == FitFault::TurnBack || f == FitFault::FaceHidden; };
    const auto awayFault = [](FitFault f) { return f == FitFault::TurnMore || f == FitFault::NotProfile; };
    std::printf("%4s %4s %5s  %-8s %7s  %s\n", "seed", "yaw", "nose", "guide", "rms mm", "fit");
    for (unsigned seed = 1; seed <= kPeople; ++seed)
        for (const int yaw : kYaws) {
            MakeHumanVisitorOptions options;
            options.seed = seed;
            options.sideNoseImageRight = seed % 2 == 1;
            options.sideYawDeg = yaw;
            const MakeHumanVisitor person = makeMakeHumanVisitor(*base, renderer, options);
            const SyntheticVisitor& v = person.photos;
            SCOPED_TRACE("seed " + std::to_string(seed) + ", yaw " + std::to_string(yaw));
            const Hint hint = sideHint(analyser.observeSide(v.side, v.background));
            std::optional<FitOutcome> o;
            std::string failure;
            try {
                o = pipeline.fit(v.front, v.side, v.background);
            } catch (const FitError& e) {
                failure = e.what();
                fitWrongWay += (yaw >= 110 && awayFault(e.fault())) || (yaw <= 70 && towardsCameraFault(e.fault()));
                rightWayAt60 += yaw == 60 && e.fault() == FitFault::TurnMore && hint == Hint::TurnMore;
                rightWayAt120 += yaw == 120 && towardsCameraFault(e.fault()) && towardsCamera(hint);
                if (e.fault() == FitFault::TurnBack) {
                    fitTurnBackAt120 += yaw == 120;
                    fitTurnBackWrongly += yaw != 120;
                    EXPECT_NE(failure.find("turn about"), std::string::npos) << "the error says how far: " << failure;
                }
            } catch (const BoothError& e) {
                failure = e.what();
            }
            turnMoreAt60 += yaw == 60 && hint == Hint::TurnMore;
            turnBackAt120 += yaw == 120 && hint == Hint::TurnBack;
            turnBackWrongly += yaw >= 70 && yaw <= 110 && hint == Hint::TurnBack;
            guideWrongWay += (yaw >= 110 && hint == Hint::TurnMore) || (yaw <= 70 && towardsCamera(hint));
            turnMoreWrongly += yaw >= 70 && yaw <= 110 && hint == Hint::TurnMore;
            double r = std::nan("");
            if (o) {
                r = faceRms(o->fit.mesh, v.truthMesh, face, options.mmPerPixel / o->fit.front.mmPerPixel);
                rms[yaw].push_back(r);
            }
            std::string cues = "-";
            try {
                SideOptions silhouetteOnly;
                silhouetteOnly.rejectFrontViews = false;
                silhouetteOnly.refusePastProfile = false;
                const SideAnalysis a = analyseSidePhoto(v.side, v.background, silhouetteOnly);
                pastAt120 += yaw == 120 && a.turn.pastProfile;
                pastWrongly += yaw >= 70 && yaw <= 110 && a.turn.pastProfile;
                cues = cv::format("eye %.3f turn %+.0f ear %s %.2f (%.3f of the head) fold %.2f%s", a.turn.eyeBehind,
                                  a.turn.degrees, a.turn.ear.found ? "at" : "-", a.turn.ear.front,
                                  a.turn.ear.headLength > 0.0 ? a.turn.ear.front / a.turn.ear.headLength : 0.0,
                                  a.turn.ear.fold, a.turn.pastProfile ? " past" : "");
            } catch (const BoothError&) {
            }
            if (o)  // the side photo's eye against the head's: how far the texture reads the side photo shifted
                std::printf("     side photo's eye %s (contrast %.0f): %.1f mm forward, %.1f mm up of the head's\n",
                            o->fit.sideEyeFound ? "used" : o->sideEye.found ? "off the eye's height" : "not found",
                            o->sideEye.contrast, o->fit.eyeLeftMm.x, o->fit.eyeLeftMm.y);
            std::printf("%4u %4d %5s  %-8s %7.2f  %s | %s\n", seed, yaw, options.sideNoseImageRight ? "right" : "left",
                        toString(hint), r, cues.c_str(), o ? "fitted" : failure.c_str());
            if (!out.empty()) {
                const fs::path dir = out / ("seed" + std::to_string(seed) + "_yaw" + std::to_string(yaw));
                fs::create_directories(dir);
                writeFileAtomically(dir / "side.png", encodeImage(v.side, ".png"));
                writeFileAtomically(dir / "background.png", encodeImage(v.background, ".png"));
                if (o) writeFileAtomically(dir / "side_overlay.jpg", encodeImage(drawSideOverlayWithRays(*o), ".jpg", 90));
            }
        }
    std::printf("median face RMS (mm) by yaw:");
    for (const int yaw : kYaws) std::printf(" %d: %.2f (%zu fitted)", yaw, median(rms[yaw]), rms[yaw].size());
    std::printf("\nside guide at 60 degrees: %d of %u say turn more; at 120: %d of %u say turn back (%d at 70-110)\n",
                turnMoreAt60, kPeople, turnBackAt120, kPeople, turnBackWrongly);
    std::printf("side analysis: %d of %u past the profile at 120 degrees (%d at 70-110)\n", pastAt120, kPeople,
                pastWrongly);
    std::printf("fit: %d of %u refused as turned past the profile at 120 degrees (%d elsewhere)\n", fitTurnBackAt120,
                kPeople, fitTurnBackWrongly);
    std::printf("refused, fit and guide saying the right way: at 60 degrees %d of %u, at 120 %d of %u (the others "
                "fit); the wrong way: the guide %d, the fit %d\n", rightWayAt60, kPeople, rightWayAt120, kPeople,
                guideWrongWay, fitWrongWay);
    // Told the wrong way: at 120 degrees seeds 2 and 3 (no nose on the outline) were told "turn more" until the
    // missing face said which way (analyseSidePhoto, PreviewAnalyser::observeSide).
    EXPECT_EQ(guideWrongWay, 0) << "the side guide told a visitor the wrong way to turn";
    EXPECT_EQ(fitWrongWay, 0) << "the fit told a visitor the wrong way to turn";
    EXPECT_GE(rightWayAt120, 4);
    // "Turn more" where the outline is a profile only when the eye, the ear and dlib's face agree
    // (turnedShortCues): measured 3 of the 4 such visitors at 60 degrees, none at 70-110.
    EXPECT_EQ(turnMoreWrongly, 0) << "the side guide told a visitor turned 70-110 degrees to turn more";
    EXPECT_GE(rightWayAt60, 5);
    // "Turn a little back" only when the ear and the eye agree (README, issue 22): never at 70-110 degrees; at 120
    // measured 2 of 6 (the ear's place differs between people by about as much as it moves from 110 to 120).
    EXPECT_EQ(turnBackWrongly, 0) << "the side guide told a visitor turned 70-110 degrees to turn back";
    EXPECT_EQ(pastWrongly, 0) << "a visitor turned 70-110 degrees read as past the profile";
    EXPECT_GE(turnBackAt120, 2);
    EXPECT_GE(pastAt120, 2);
    // The fit refuses on the same cue (SideOptions::refusePastProfile): every visitor the side analysis reads as
    // past at 120 degrees whose outline is a profile, and nobody nearer the profile.
    EXPECT_EQ(fitTurnBackWrongly, 0) << "the fit told a visitor not at 120 degrees to turn back";
    EXPECT_GE(fitTurnBackAt120, 2);
    // Measured (6 people): 70 and 110 2.17 mm, 80 and 100 1.75, 90 1.59; every one fitted.
    for (const int yaw : {70, 80, 90, 100, 110}) {
        EXPECT_EQ(rms[yaw].size(), kPeople) << "yaw " << yaw << ": every visitor fits";
        EXPECT_LT(median(rms[yaw]), 1.6 * median(rms[90])) << "yaw " << yaw;
    }
}
