// The visitor flow from lists of events: every transition, every timeout, retakes, failures, the lost camera, the
// operator lock. Commands are compared as their describe() strings, in order.
#include "booth/visitor_flow.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

using namespace avatarbooth;

namespace {

FlowTime at(double seconds) {
    return FlowTime{} + std::chrono::round<FlowClock::duration>(std::chrono::duration<double>(seconds));
}

using Names = std::vector<std::string>;

Names names(const std::vector<FlowCommand>& commands) {
    Names out;
    for (const auto& c : commands) out.push_back(describe(c));
    return out;
}

const std::string kLampsAttract = "SetLamps(start=slow,retake=off,flash=off)";
const std::string kLampsGuide = "SetLamps(start=on,retake=off,flash=off)";
const std::string kLampsOff = "SetLamps(start=off,retake=off,flash=off)";
const std::string kLampsFlash = "SetLamps(start=off,retake=off,flash=on)";
const std::string kLampsBoth = "SetLamps(start=on,retake=on,flash=off)";

// A booth driven by a script; `now` is the time of the last event, in seconds.
class Booth {
public:
    explicit Booth(BoothSettings s = {}) : flow(std::move(s), at(0)) {}

    Names send(const FlowEvent& e) {
        now = std::chrono::duration<double>(eventTime(e) - FlowTime{}).count();
        return names(flow.handle(e));
    }
    Names tickAt(double s) { return send(Tick{at(s)}); }
    Names after(double dt) { return tickAt(now + dt); }
    // A press `dt` after the last event (past the press guard) and its release 0.1 s later.
    Names press(Button b, double dt = 1.0) {
        Names out = send(ButtonPressed{b, at(now + dt)});
        const Names rel = send(ButtonReleased{b, at(now + 0.1)});
        out.insert(out.end(), rel.begin(), rel.end());
        return out;
    }
    Names down(Button b, double dt = 1.0) { return send(ButtonPressed{b, at(now + dt)}); }
    Names up(Button b, double dt = 0.1) { return send(ButtonReleased{b, at(now + dt)}); }
    Names analysed(Photo p, Hint h, double dt = 0.1, bool person = true) {
        return send(PreviewAnalysed{p, h, person, at(now + dt)});
    }
    Names captured(Photo p, double dt = 0.2) { return send(CaptureDone{p, at(now + dt)}); }
    Names lost(double dt = 0.1) { return send(CameraLost{"/dev/video0: No such device", at(now + dt)}); }
    Names back(double dt = 0.1) { return send(CameraBack{at(now + dt)}); }

    ScreenId screen() const { return flow.screen().id; }
    const ScreenModel& model() const { return flow.screen(); }

    // Scripts to each state.
    void toFrontGuide() {
        press(Button::Start);
        ASSERT_EQ(screen(), ScreenId::FrontGuide);
    }
    void toCountdown(Photo p) {
        press(Button::Start);
        ASSERT_EQ(screen(), ScreenId::Countdown);
        ASSERT_EQ(model().photo, p);
    }
    void toCapture(Photo p) {
        toCountdown(p);
        after(3.0);
        ASSERT_EQ(screen(), ScreenId::CaptureFlash);
    }
    void toSideGuide() {
        toFrontGuide();
        toCapture(Photo::Front);
        captured(Photo::Front);
        ASSERT_EQ(screen(), ScreenId::SideGuide);
    }
    void toProcessing() {
        toSideGuide();
        toCapture(Photo::Side);
        captured(Photo::Side);
        ASSERT_EQ(screen(), ScreenId::Processing);
    }
    void toReveal() {
        toProcessing();
        send(FitDone{at(now + 2.0)});
        ASSERT_EQ(screen(), ScreenId::Reveal);
    }
    void toRetakeChoice() {
        toReveal();
        press(Button::Retake);
        ASSERT_EQ(screen(), ScreenId::RetakeChoice);
    }
    void toThanks() {
        toReveal();
        press(Button::Start);
        ASSERT_EQ(screen(), ScreenId::Thanks);
    }
    void toOperator() {
        down(Button::Retake);
        down(Button::Start, 0.1);
        after(5.0);
        ASSERT_EQ(screen(), ScreenId::OperatorMenu);
        up(Button::Start);
        up(Button::Retake);
    }

    VisitorFlow flow;
    double now = 0.0;
};

}  // namespace

// ------------------------------------------------------------------------------------------- the happy path

TEST(VisitorFlow, StartsOnAttractWithTheStartLampBlinking) {
    Booth b;
    EXPECT_EQ(b.screen(), ScreenId::Attract);
    EXPECT_EQ(names(b.flow.initialCommands()), Names{kLampsAttract});
    EXPECT_EQ(b.after(600.0), Names{});  // attract has no timeout of its own
    EXPECT_EQ(b.screen(), ScreenId::Attract);
}

TEST(VisitorFlow, WholeSessionKept) {
    Booth b;
    EXPECT_EQ(b.press(Button::Start), (Names{kLampsGuide, "StartPreview(front)"}));
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    EXPECT_EQ(b.model().hint, Hint::None);

    EXPECT_EQ(b.analysed(Photo::Front, Hint::StepCloser), Names{});
    EXPECT_EQ(b.model().hint, Hint::StepCloser);
    b.analysed(Photo::Front, Hint::HoldStill);  // at t0
    const double t0 = b.now;
    b.tickAt(t0 + 0.999);
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    EXPECT_EQ(b.model().hint, Hint::HoldStill);
    EXPECT_EQ(b.tickAt(t0 + 1.0), Names{kLampsOff});  // steady for 1 s: the countdown starts by itself
    EXPECT_EQ(b.screen(), ScreenId::Countdown);
    EXPECT_EQ(b.model().photo, Photo::Front);
    EXPECT_EQ(b.model().countdown, 3);
    EXPECT_EQ(b.model().countdownAge, Millis(0));
    b.tickAt(t0 + 1.999);
    EXPECT_EQ(b.model().countdown, 3);
    EXPECT_LE(std::abs(b.model().countdownAge.count() - 999), 1);  // (the test's seconds are doubles)
    b.tickAt(t0 + 2.0);
    EXPECT_EQ(b.model().countdown, 2);
    EXPECT_LE(std::abs(b.model().countdownAge.count()), 1);
    b.tickAt(t0 + 3.5);
    EXPECT_EQ(b.model().countdown, 1);
    EXPECT_LE(std::abs(b.model().countdownAge.count() - 500), 1);  // the beep for 1 was due 500 ms before this step
    EXPECT_EQ(b.tickAt(t0 + 4.0), (Names{kLampsFlash, "CapturePhoto(front)"}));
    EXPECT_EQ(b.screen(), ScreenId::CaptureFlash);

    EXPECT_EQ(b.captured(Photo::Front), (Names{kLampsGuide, "StartPreview(side)"}));
    EXPECT_EQ(b.screen(), ScreenId::SideGuide);
    EXPECT_EQ(b.model().photo, Photo::Side);
    b.analysed(Photo::Side, Hint::TurnRight);
    EXPECT_EQ(b.model().hint, Hint::TurnRight);
    b.analysed(Photo::Side, Hint::TurnMore);
    EXPECT_EQ(b.model().hint, Hint::TurnMore);
    b.analysed(Photo::Side, Hint::HoldStill);
    EXPECT_EQ(b.analysed(Photo::Side, Hint::HoldStill, 1.0), Names{kLampsOff});
    EXPECT_EQ(b.screen(), ScreenId::Countdown);
    EXPECT_EQ(b.model().photo, Photo::Side);
    EXPECT_EQ(b.after(3.0), (Names{kLampsFlash, "CapturePhoto(side)"}));
    EXPECT_EQ(b.captured(Photo::Side), (Names{"StopPreview", kLampsOff, "StartFit"}));
    EXPECT_EQ(b.screen(), ScreenId::Processing);
    EXPECT_EQ(b.model().progress, 0.0);

    b.send(FitProgress{FitStep::HeadFit, at(b.now + 0.5)});
    EXPECT_EQ(b.model().progress, 0.4);
    EXPECT_EQ(b.model().fitStep, FitStep::HeadFit);
    EXPECT_EQ(b.send(FitDone{at(b.now + 0.5)}), Names{kLampsBoth});
    EXPECT_EQ(b.screen(), ScreenId::Reveal);

    EXPECT_EQ(b.press(Button::Start), (Names{kLampsOff, "SaveSession"}));
    EXPECT_EQ(b.screen(), ScreenId::Thanks);
    EXPECT_EQ(b.model().code, "");
    b.send(SessionSaved{"AB3K7Z", at(b.now + 0.1)});
    EXPECT_EQ(b.model().code, "AB3K7Z");
    const double savedAt = b.now;  // the code shows its 20 s from when it is known
    b.tickAt(savedAt + 19.99);
    EXPECT_EQ(b.screen(), ScreenId::Thanks);
    EXPECT_EQ(b.tickAt(savedAt + 20.0), Names{kLampsAttract});  // kept: nothing to discard
    EXPECT_EQ(b.screen(), ScreenId::Attract);
}

TEST(VisitorFlow, ABreakInHoldStillRestartsTheSteadyTime) {
    Booth b;
    b.toFrontGuide();
    b.analysed(Photo::Front, Hint::HoldStill);
    b.analysed(Photo::Front, Hint::HoldStill, 0.8);
    b.analysed(Photo::Front, Hint::LookAtCamera, 0.1);
    b.analysed(Photo::Front, Hint::HoldStill, 0.1);
    b.after(0.9);
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    b.after(0.1);
    EXPECT_EQ(b.screen(), ScreenId::Countdown);
}

TEST(VisitorFlow, AnalysesForTheOtherGuideAreIgnored) {
    Booth b;
    b.toFrontGuide();
    b.analysed(Photo::Side, Hint::HoldStill);
    b.after(2.0);
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    EXPECT_EQ(b.model().hint, Hint::None);
}

TEST(VisitorFlow, StartInAGuideStartsTheCountdownAtOnce) {
    Booth b;
    b.toFrontGuide();
    b.analysed(Photo::Front, Hint::StepBack);
    EXPECT_EQ(b.press(Button::Start), Names{kLampsOff});
    EXPECT_EQ(b.screen(), ScreenId::Countdown);
}

TEST(VisitorFlow, RetakeButtonDoesNothingInAttractGuidesAndCountdown) {
    Booth b;
    EXPECT_EQ(b.press(Button::Retake), Names{});
    EXPECT_EQ(b.screen(), ScreenId::Attract);
    b.toFrontGuide();
    EXPECT_EQ(b.press(Button::Retake), Names{});
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    b.toCountdown(Photo::Front);
    EXPECT_EQ(b.press(Button::Retake, 0.6), Names{});
    EXPECT_EQ(b.press(Button::Start, 0.1), Names{});
    EXPECT_EQ(b.screen(), ScreenId::Countdown);
}

// ----------------------------------------------------------------------------------------- presses and bounces

TEST(VisitorFlow, PressesDuringProcessingAreIgnored) {
    Booth b;
    b.toProcessing();
    for (int i = 0; i < 5; ++i) {
        EXPECT_EQ(b.press(Button::Start), Names{});
        EXPECT_EQ(b.press(Button::Retake), Names{});
        EXPECT_EQ(b.screen(), ScreenId::Processing);
    }
    EXPECT_EQ(b.send(FitDone{at(b.now + 0.1)}), Names{kLampsBoth});
    EXPECT_EQ(b.screen(), ScreenId::Reveal);
}

TEST(VisitorFlow, PressesDuringCaptureAreIgnored) {
    Booth b;
    b.toFrontGuide();
    b.toCapture(Photo::Front);
    EXPECT_EQ(b.press(Button::Start, 0.6), Names{});
    EXPECT_EQ(b.press(Button::Retake, 0.1), Names{});
    EXPECT_EQ(b.screen(), ScreenId::CaptureFlash);
}

TEST(VisitorFlow, BouncingPressCountsOnce) {
    Booth b;
    // Three press edges without a release between them (a driver that let a bounce through): one press.
    EXPECT_EQ(b.down(Button::Start), (Names{kLampsGuide, "StartPreview(front)"}));
    EXPECT_EQ(b.down(Button::Start, 0.6), Names{});
    EXPECT_EQ(b.down(Button::Start, 0.6), Names{});
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    b.up(Button::Start);
    // Pressed again after the release: a new press, the countdown starts.
    EXPECT_EQ(b.down(Button::Start, 0.5), Names{kLampsOff});
    EXPECT_EQ(b.screen(), ScreenId::Countdown);
}

TEST(VisitorFlow, DoublePressDoesNotAlsoActOnTheNextScreen) {
    Booth b;
    b.press(Button::Start, 1.0);
    ASSERT_EQ(b.screen(), ScreenId::FrontGuide);
    // The second press of a double press lands 0.3 s into the guide: within the 0.5 s guard.
    EXPECT_EQ(b.press(Button::Start, 0.2), Names{});
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    // At 0.5 s it counts.
    b.send(ButtonPressed{Button::Start, at(1.5)});
    EXPECT_EQ(b.screen(), ScreenId::Countdown);
}

// --------------------------------------------------------------------------------------------------- timeouts

TEST(VisitorFlow, GuideTimesOutWhenNobodyIsSeen) {
    Booth b;
    b.toFrontGuide();
    const double t0 = b.now - 0.1;  // entered at the press
    b.tickAt(t0 + 19.9);
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    EXPECT_EQ(b.tickAt(t0 + 20.0), (Names{"StopPreview", "DiscardSession", kLampsAttract}));
    EXPECT_EQ(b.screen(), ScreenId::Attract);
}

TEST(VisitorFlow, GuideTimeoutCountsFromTheLastPersonSeen) {
    Booth b;
    b.toFrontGuide();
    const double t0 = b.now - 0.1;
    b.send(PreviewAnalysed{Photo::Front, Hint::StepCloser, true, at(t0 + 15.0)});
    b.send(PreviewAnalysed{Photo::Front, Hint::NoFace, false, at(t0 + 16.0)});
    b.tickAt(t0 + 34.9);
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    b.tickAt(t0 + 35.0);
    EXPECT_EQ(b.screen(), ScreenId::Attract);
}

TEST(VisitorFlow, GuideGivesUpAfterItsMaximumTimeEvenWithSomeoneThere) {
    Booth b;
    b.toFrontGuide();
    const double t0 = b.now - 0.1;
    for (double t = t0 + 5.0; t < t0 + 120.0; t += 5.0)
        b.send(PreviewAnalysed{Photo::Front, Hint::StepCloser, true, at(t)});
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    EXPECT_EQ(b.tickAt(t0 + 120.0), (Names{"StopPreview", "DiscardSession", kLampsAttract}));
    EXPECT_EQ(b.screen(), ScreenId::Attract);
}

TEST(VisitorFlow, SideGuideTimesOut) {
    Booth b;
    b.toSideGuide();
    EXPECT_EQ(b.after(20.0), (Names{"StopPreview", "DiscardSession", kLampsAttract}));
    EXPECT_EQ(b.screen(), ScreenId::Attract);
}

TEST(VisitorFlow, CaptureTimesOutBackToItsGuide) {
    Booth b;
    b.toFrontGuide();
    b.toCapture(Photo::Front);
    b.after(9.9);
    EXPECT_EQ(b.screen(), ScreenId::CaptureFlash);
    EXPECT_EQ(b.after(0.1), Names{kLampsGuide});  // the preview never stopped
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    EXPECT_EQ(b.model().banner, BannerKind::CaptureFailed);
    // A late photo for the capture that timed out is ignored.
    EXPECT_EQ(b.captured(Photo::Front), Names{});
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
}

TEST(VisitorFlow, ProcessingTimesOutCancellingTheFit) {
    Booth b;
    b.toProcessing();
    b.after(89.9);
    EXPECT_EQ(b.screen(), ScreenId::Processing);
    EXPECT_EQ(b.after(0.1), (Names{"CancelFit", "DiscardSession", kLampsAttract}));
    EXPECT_EQ(b.screen(), ScreenId::Attract);
    // The fit's late answer changes nothing.
    EXPECT_EQ(b.send(FitDone{at(b.now + 1.0)}), Names{});
    EXPECT_EQ(b.screen(), ScreenId::Attract);
}

TEST(VisitorFlow, RevealTimesOutDiscardingTheSession) {
    Booth b;
    b.toReveal();
    b.after(59.9);
    EXPECT_EQ(b.screen(), ScreenId::Reveal);
    EXPECT_EQ(b.after(0.1), (Names{"DiscardSession", kLampsAttract}));
    EXPECT_EQ(b.screen(), ScreenId::Attract);
}

TEST(VisitorFlow, RetakeChoiceTimesOutBackToTheReveal) {
    Booth b;
    b.toRetakeChoice();
    const double t0 = b.now - 0.1;
    b.tickAt(t0 + 19.9);
    EXPECT_EQ(b.screen(), ScreenId::RetakeChoice);
    EXPECT_EQ(b.tickAt(t0 + 20.0), Names{});  // same lamps
    EXPECT_EQ(b.screen(), ScreenId::Reveal);
    // ... whose own timeout then starts afresh.
    b.tickAt(t0 + 20.0 + 59.9);
    EXPECT_EQ(b.screen(), ScreenId::Reveal);
    b.tickAt(t0 + 20.0 + 60.0);
    EXPECT_EQ(b.screen(), ScreenId::Attract);
}

TEST(VisitorFlow, ThanksIgnoresStartAtFirstThenStartsANewSession) {
    Booth b;
    b.toThanks();
    const double t0 = b.now - 0.1;
    b.send(SessionSaved{"AB3K7Z", at(t0 + 0.2)});
    b.send(ButtonPressed{Button::Start, at(t0 + 4.9)});
    b.send(ButtonReleased{Button::Start, at(t0 + 4.95)});
    EXPECT_EQ(b.screen(), ScreenId::Thanks);
    EXPECT_EQ(b.send(ButtonPressed{Button::Start, at(t0 + 5.0)}), (Names{kLampsGuide, "StartPreview(front)"}));
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    EXPECT_EQ(b.model().code, "");
}

TEST(VisitorFlow, ThanksShowsASaveFailure) {
    Booth b;
    b.toThanks();
    b.send(SessionSaveFailed{"/var/lib/avatarbooth/sessions: No space left on device", at(b.now + 0.2)});
    EXPECT_EQ(b.model().banner, BannerKind::SaveFailed);
    EXPECT_EQ(b.model().code, "");
    b.after(20.0);
    EXPECT_EQ(b.screen(), ScreenId::Attract);
    EXPECT_EQ(b.model().banner, BannerKind::None);
}

TEST(VisitorFlow, ThanksWaitsForASlowSaveThenShowsTheCodeItsFullTime) {
    Booth b;
    b.toThanks();
    const double entered = b.now - 0.1;  // the press that kept the session (its release came 0.1 s later)
    EXPECT_EQ(b.tickAt(entered + 45.0), Names{});  // still "saving": the visitor waits for the code
    EXPECT_EQ(b.screen(), ScreenId::Thanks);
    EXPECT_EQ(b.model().code, "");
    b.send(SessionSaved{"AB3K7Z", at(entered + 50.0)});
    EXPECT_EQ(b.model().code, "AB3K7Z");
    b.tickAt(entered + 69.9);
    EXPECT_EQ(b.screen(), ScreenId::Thanks);  // 20 s of code from when it came, not from the keep
    EXPECT_EQ(b.tickAt(entered + 70.0), Names{kLampsAttract});
    EXPECT_EQ(b.screen(), ScreenId::Attract);
}

TEST(VisitorFlow, ThanksGivesUpWaitingForTheSaveAfterItsLimit) {
    BoothSettings s;
    s.thanksSavingLimit = Millis(30000);
    Booth b(s);
    b.toThanks();
    const double entered = b.now - 0.1;
    b.tickAt(entered + 29.9);
    EXPECT_EQ(b.screen(), ScreenId::Thanks);
    EXPECT_EQ(b.tickAt(entered + 30.0), Names{kLampsAttract});
    EXPECT_EQ(b.screen(), ScreenId::Attract);
    b.send(SessionSaved{"AB3K7Z", at(entered + 31.0)});  // the write ended after all: nothing shows it to the next visitor
    EXPECT_EQ(b.model().code, "");
}

// ------------------------------------------------------------------------------------------------------ retakes

TEST(VisitorFlow, RetakeFrontKeepsTheSidePhoto) {
    Booth b;
    b.toRetakeChoice();
    EXPECT_EQ(b.press(Button::Start), (Names{kLampsGuide, "StartPreview(front)"}));
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    b.toCapture(Photo::Front);
    EXPECT_EQ(b.captured(Photo::Front), (Names{"StopPreview", kLampsOff, "StartFit"}));
    EXPECT_EQ(b.screen(), ScreenId::Processing);
    b.send(FitDone{at(b.now + 1.0)});
    EXPECT_EQ(b.screen(), ScreenId::Reveal);
}

TEST(VisitorFlow, RetakeSideKeepsTheFrontPhoto) {
    Booth b;
    b.toRetakeChoice();
    EXPECT_EQ(b.press(Button::Retake), (Names{kLampsGuide, "StartPreview(side)"}));
    EXPECT_EQ(b.screen(), ScreenId::SideGuide);
    b.toCapture(Photo::Side);
    EXPECT_EQ(b.captured(Photo::Side), (Names{"StopPreview", kLampsOff, "StartFit"}));
    EXPECT_EQ(b.screen(), ScreenId::Processing);
}

TEST(VisitorFlow, RetakeTwiceThenKeep) {
    Booth b;
    b.toRetakeChoice();
    b.press(Button::Retake);
    b.toCapture(Photo::Side);
    b.captured(Photo::Side);
    b.send(FitDone{at(b.now + 1.0)});
    b.press(Button::Retake);
    b.press(Button::Start);
    ASSERT_EQ(b.screen(), ScreenId::FrontGuide);
    b.toCapture(Photo::Front);
    b.captured(Photo::Front);
    b.send(FitDone{at(b.now + 1.0)});
    EXPECT_EQ(b.press(Button::Start), (Names{kLampsOff, "SaveSession"}));
}

// --------------------------------------------------------------------------------------------- fit failures

TEST(VisitorFlow, NoFaceInTheFrontPhotoGoesBackToTheFrontGuide) {
    Booth b;
    b.toProcessing();
    EXPECT_EQ(b.send(FitFailed{RetakeWhich::Front, FitFailure::NoFace, "front.jpg: no face found", at(b.now + 1)}),
              (Names{kLampsGuide, "StartPreview(front)"}));
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    EXPECT_EQ(b.model().banner, BannerKind::FitFailed);
    EXPECT_EQ(b.model().fitFailure, FitFailure::NoFace);
    EXPECT_EQ(b.model().detail, "front.jpg: no face found");
    // The banner stays through the guide and goes when the new countdown starts.
    b.analysed(Photo::Front, Hint::HoldStill);
    EXPECT_EQ(b.model().banner, BannerKind::FitFailed);
    b.toCapture(Photo::Front);
    EXPECT_EQ(b.model().banner, BannerKind::None);
    // The side photo stands: straight to processing.
    EXPECT_EQ(b.captured(Photo::Front), (Names{"StopPreview", kLampsOff, "StartFit"}));
}

TEST(VisitorFlow, NoProfileInTheSidePhotoGoesBackToTheSideGuide) {
    Booth b;
    b.toProcessing();
    b.send(FitFailed{RetakeWhich::Side, FitFailure::NotProfile, "side.jpg: a front view", at(b.now + 1)});
    EXPECT_EQ(b.screen(), ScreenId::SideGuide);
    EXPECT_EQ(b.model().fitFailure, FitFailure::NotProfile);
    b.toCapture(Photo::Side);
    EXPECT_EQ(b.captured(Photo::Side), (Names{"StopPreview", kLampsOff, "StartFit"}));
}

TEST(VisitorFlow, PhotosThatDoNotMatchAreBothRetaken) {
    Booth b;
    b.toProcessing();
    b.send(FitFailed{RetakeWhich::Both, FitFailure::Mismatch, "head sizes disagree", at(b.now + 1)});
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    EXPECT_EQ(b.model().fitFailure, FitFailure::Mismatch);
    b.toCapture(Photo::Front);
    EXPECT_EQ(b.captured(Photo::Front), (Names{kLampsGuide, "StartPreview(side)"}));
    EXPECT_EQ(b.screen(), ScreenId::SideGuide);
    b.toCapture(Photo::Side);
    EXPECT_EQ(b.captured(Photo::Side), (Names{"StopPreview", kLampsOff, "StartFit"}));
}

TEST(VisitorFlow, FailedFitAfterARetakeGoesBackToThatGuide) {
    Booth b;
    b.toRetakeChoice();
    b.press(Button::Retake);
    b.toCapture(Photo::Side);
    b.captured(Photo::Side);
    b.send(FitFailed{RetakeWhich::Side, FitFailure::NotProfile, "", at(b.now + 1)});
    EXPECT_EQ(b.screen(), ScreenId::SideGuide);
}

TEST(VisitorFlow, CaptureFailureGoesBackToThatGuide) {
    Booth b;
    b.toSideGuide();
    b.toCapture(Photo::Side);
    EXPECT_EQ(b.send(CaptureFailed{Photo::Side, "VIDIOC_DQBUF: timeout", at(b.now + 0.5)}), Names{kLampsGuide});
    EXPECT_EQ(b.screen(), ScreenId::SideGuide);
    EXPECT_EQ(b.model().banner, BannerKind::CaptureFailed);
    EXPECT_EQ(b.model().detail, "VIDIOC_DQBUF: timeout");
}

TEST(VisitorFlow, FitFailureWithTheWalkAwayStillTimesOut) {
    Booth b;
    b.toProcessing();
    b.send(FitFailed{RetakeWhich::Front, FitFailure::NoFace, "", at(b.now + 1)});
    EXPECT_EQ(b.after(20.0), (Names{"StopPreview", "DiscardSession", kLampsAttract}));
    EXPECT_EQ(b.screen(), ScreenId::Attract);
}

// ------------------------------------------------------------------------------------------- the lost camera

TEST(VisitorFlow, CameraLostOnAttractBlocksTheStartUntilItIsBack) {
    Booth b;
    EXPECT_EQ(b.lost(), Names{kLampsOff});
    EXPECT_EQ(b.screen(), ScreenId::Attract);
    EXPECT_EQ(b.model().banner, BannerKind::CameraLost);
    EXPECT_EQ(b.model().detail, "/dev/video0: No such device");
    EXPECT_FALSE(b.model().cameraAvailable);
    EXPECT_EQ(b.press(Button::Start), Names{});
    EXPECT_EQ(b.screen(), ScreenId::Attract);
    EXPECT_EQ(b.back(), Names{kLampsAttract});
    EXPECT_EQ(b.model().banner, BannerKind::None);
    EXPECT_TRUE(b.model().cameraAvailable);
    EXPECT_EQ(b.press(Button::Start), (Names{kLampsGuide, "StartPreview(front)"}));
}

TEST(VisitorFlow, CameraLostInTheFrontGuideResumesThere) {
    Booth b;
    b.toFrontGuide();
    EXPECT_EQ(b.lost(), (Names{"StopPreview", kLampsOff}));
    EXPECT_EQ(b.screen(), ScreenId::CameraLost);
    EXPECT_EQ(b.press(Button::Start), Names{});
    EXPECT_EQ(b.back(), (Names{kLampsGuide, "StartPreview(front)"}));
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
}

TEST(VisitorFlow, CameraLostInTheSideGuideResumesThere) {
    Booth b;
    b.toSideGuide();
    EXPECT_EQ(b.lost(), (Names{"StopPreview", kLampsOff}));
    EXPECT_EQ(b.screen(), ScreenId::CameraLost);
    EXPECT_EQ(b.back(), (Names{kLampsGuide, "StartPreview(side)"}));
    EXPECT_EQ(b.screen(), ScreenId::SideGuide);
    // The front photo was kept: after the side capture, processing.
    b.toCapture(Photo::Side);
    EXPECT_EQ(b.captured(Photo::Side), (Names{"StopPreview", kLampsOff, "StartFit"}));
}

TEST(VisitorFlow, CameraLostInTheCountdownResumesAtItsGuide) {
    Booth b;
    b.toFrontGuide();
    b.toCountdown(Photo::Front);
    EXPECT_EQ(b.lost(), Names{"StopPreview"});  // countdown and camera-lost lamps are both off
    EXPECT_EQ(b.screen(), ScreenId::CameraLost);
    b.after(5.0);  // the countdown's end passes: no capture while the camera is away
    EXPECT_EQ(b.screen(), ScreenId::CameraLost);
    EXPECT_EQ(b.back(), (Names{kLampsGuide, "StartPreview(front)"}));
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
}

TEST(VisitorFlow, CameraLostDuringCaptureRetakesThatPhoto) {
    Booth b;
    b.toSideGuide();
    b.toCapture(Photo::Side);
    EXPECT_EQ(b.lost(), (Names{"StopPreview", kLampsOff}));
    EXPECT_EQ(b.screen(), ScreenId::CameraLost);
    EXPECT_EQ(b.captured(Photo::Side), Names{});  // a photo from before the loss is not trusted
    EXPECT_EQ(b.back(), (Names{kLampsGuide, "StartPreview(side)"}));
    EXPECT_EQ(b.screen(), ScreenId::SideGuide);
}

TEST(VisitorFlow, CameraLostDuringProcessingCarriesOnWithABanner) {
    Booth b;
    b.toProcessing();
    EXPECT_EQ(b.lost(), Names{});
    EXPECT_EQ(b.screen(), ScreenId::Processing);
    EXPECT_EQ(b.model().banner, BannerKind::CameraLost);
    b.send(FitDone{at(b.now + 1.0)});
    EXPECT_EQ(b.screen(), ScreenId::Reveal);
    EXPECT_EQ(b.model().banner, BannerKind::CameraLost);
    EXPECT_EQ(b.back(), Names{});
    EXPECT_EQ(b.model().banner, BannerKind::None);
}

TEST(VisitorFlow, CameraLostDuringProcessingThenAFailedFitWaitsForTheCamera) {
    Booth b;
    b.toProcessing();
    b.lost();
    b.send(FitFailed{RetakeWhich::Front, FitFailure::NoFace, "", at(b.now + 1.0)});
    EXPECT_EQ(b.screen(), ScreenId::CameraLost);
    EXPECT_EQ(b.back(), (Names{kLampsGuide, "StartPreview(front)"}));
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    EXPECT_EQ(b.model().banner, BannerKind::FitFailed);
}

TEST(VisitorFlow, CameraLostOnTheRevealStillKeeps) {
    Booth b;
    b.toReveal();
    EXPECT_EQ(b.lost(), Names{});
    EXPECT_EQ(b.screen(), ScreenId::Reveal);
    EXPECT_EQ(b.model().banner, BannerKind::CameraLost);
    EXPECT_EQ(b.press(Button::Start), (Names{kLampsOff, "SaveSession"}));
    EXPECT_EQ(b.screen(), ScreenId::Thanks);
    EXPECT_EQ(b.back(), Names{});
    EXPECT_EQ(b.model().banner, BannerKind::None);
}

TEST(VisitorFlow, CameraLostAndBackOnTheRevealChangesNothingElse) {
    Booth b;
    b.toReveal();
    b.lost();
    EXPECT_EQ(b.back(), Names{});
    EXPECT_EQ(b.screen(), ScreenId::Reveal);
    EXPECT_EQ(b.model().banner, BannerKind::None);
    EXPECT_EQ(b.press(Button::Retake), Names{});  // same lamps on the retake question
    EXPECT_EQ(b.screen(), ScreenId::RetakeChoice);
}

TEST(VisitorFlow, CameraLostOnTheRetakeChoiceWaitsForTheCameraThenRetakes) {
    Booth b;
    b.toRetakeChoice();
    EXPECT_EQ(b.lost(), Names{});
    EXPECT_EQ(b.press(Button::Retake), Names{kLampsOff});
    EXPECT_EQ(b.screen(), ScreenId::CameraLost);
    EXPECT_EQ(b.back(), (Names{kLampsGuide, "StartPreview(side)"}));
    EXPECT_EQ(b.screen(), ScreenId::SideGuide);
}

TEST(VisitorFlow, CameraLostOnThanksKeepsTheCodeAndBlocksANewSession) {
    Booth b;
    b.toThanks();
    b.send(SessionSaved{"AB3K7Z", at(b.now + 0.1)});
    EXPECT_EQ(b.lost(), Names{});
    EXPECT_EQ(b.screen(), ScreenId::Thanks);
    EXPECT_EQ(b.model().code, "AB3K7Z");
    EXPECT_EQ(b.press(Button::Start, 6.0), Names{});
    EXPECT_EQ(b.screen(), ScreenId::Thanks);
    b.after(20.0);
    EXPECT_EQ(b.screen(), ScreenId::Attract);
    EXPECT_EQ(b.model().banner, BannerKind::CameraLost);
}

TEST(VisitorFlow, CameraBackOnThanksAllowsTheNextSession) {
    Booth b;
    b.toThanks();
    b.lost();
    EXPECT_EQ(b.back(), Names{});
    EXPECT_EQ(b.press(Button::Start, 6.0), (Names{kLampsGuide, "StartPreview(front)"}));
}

TEST(VisitorFlow, CameraLostTooLongEndsTheSession) {
    Booth b;
    b.toSideGuide();
    b.lost();
    b.after(59.9);
    EXPECT_EQ(b.screen(), ScreenId::CameraLost);
    EXPECT_EQ(b.after(0.1), Names{"DiscardSession"});  // lamps stay off: attract without a camera
    EXPECT_EQ(b.screen(), ScreenId::Attract);
    EXPECT_EQ(b.model().banner, BannerKind::CameraLost);
    EXPECT_EQ(b.back(), Names{kLampsAttract});
}

TEST(VisitorFlow, CameraLostInTheOperatorMenuShowsNoBanner) {
    Booth b;
    b.toOperator();
    EXPECT_EQ(b.lost(), Names{});
    EXPECT_EQ(b.screen(), ScreenId::OperatorMenu);
    EXPECT_EQ(b.model().banner, BannerKind::None);
    EXPECT_FALSE(b.model().cameraAvailable);
    EXPECT_EQ(b.back(), Names{});
    EXPECT_TRUE(b.model().cameraAvailable);
}

TEST(VisitorFlow, RepeatedCameraEventsCountOnce) {
    Booth b;
    b.toFrontGuide();
    b.lost();
    EXPECT_EQ(b.lost(), Names{});
    b.back();
    EXPECT_EQ(b.back(), Names{});
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
}

// ------------------------------------------------------------------------------------------- the operator lock

TEST(VisitorFlow, LockOpensTheMenuAfterTheHoldTime) {
    Booth b;
    EXPECT_EQ(b.down(Button::Retake, 1.0), Names{});
    // Start goes down 0.1 s later; as a press it starts a session ...
    EXPECT_EQ(b.down(Button::Start, 0.1), (Names{kLampsGuide, "StartPreview(front)"}));
    const double both = b.now;
    b.tickAt(both + 4.99);
    EXPECT_EQ(b.screen(), ScreenId::FrontGuide);
    // ... which the lock discards when it opens the menu.
    EXPECT_EQ(b.tickAt(both + 5.0), (Names{"StopPreview", "DiscardSession", kLampsBoth}));
    EXPECT_EQ(b.screen(), ScreenId::OperatorMenu);
    EXPECT_EQ(b.model().menuItem, OperatorItem::LastCodes);
    EXPECT_EQ(b.model().menuPage, OperatorPage::Menu);
}

TEST(VisitorFlow, LockHeldTooShortDoesNothing) {
    Booth b;
    b.down(Button::Retake);
    b.down(Button::Retake, 0.1);
    b.down(Button::Start, 0.1);
    const double both = b.now;
    b.send(ButtonReleased{Button::Start, at(both + 4.9)});
    b.tickAt(both + 10.0);
    EXPECT_NE(b.screen(), ScreenId::OperatorMenu);
}

TEST(VisitorFlow, WrongCombinationDoesNothing) {
    Booth b;
    b.down(Button::Retake);  // Retake alone, held 30 s
    b.after(30.0);
    EXPECT_EQ(b.screen(), ScreenId::Attract);
    b.up(Button::Retake);

    Booth c;
    c.down(Button::Start);  // Start alone (starts a session), held 6 s
    c.after(6.0);
    EXPECT_NE(c.screen(), ScreenId::OperatorMenu);

    Booth d;  // the combination plus a button not in it
    d.down(Button::Service);
    d.down(Button::Retake, 0.1);
    d.down(Button::Start, 0.1);
    d.after(6.0);
    EXPECT_NE(d.screen(), ScreenId::OperatorMenu);
}

TEST(VisitorFlow, ConfiguredServiceButtonLock) {
    BoothSettings s;
    s.lockCombo = {Button::Service};
    s.lockHold = Millis(2000);
    Booth b(s);
    b.down(Button::Service);
    b.after(1.9);
    EXPECT_EQ(b.screen(), ScreenId::Attract);
    b.after(0.1);
    EXPECT_EQ(b.screen(), ScreenId::OperatorMenu);
}

TEST(VisitorFlow, LockDuringProcessingCancelsTheFit) {
    Booth b;
    b.toProcessing();
    b.down(Button::Start);
    b.down(Button::Retake, 0.1);
    EXPECT_EQ(b.after(5.0), (Names{"CancelFit", "DiscardSession", kLampsBoth}));
    EXPECT_EQ(b.screen(), ScreenId::OperatorMenu);
}

TEST(VisitorFlow, LockAfterAKeptSessionDiscardsNothing) {
    Booth b;
    b.toThanks();
    b.down(Button::Start, 0.5);
    b.down(Button::Retake, 0.1);
    EXPECT_EQ(b.after(5.0), Names{kLampsBoth});
    EXPECT_EQ(b.screen(), ScreenId::OperatorMenu);
}

TEST(VisitorFlow, OperatorMenuItemsAndPages) {
    Booth b;
    b.toOperator();
    EXPECT_EQ(b.model().menuItem, OperatorItem::LastCodes);
    EXPECT_EQ(b.press(Button::Start), Names{});
    EXPECT_EQ(b.model().menuPage, OperatorPage::LastCodes);
    EXPECT_EQ(b.press(Button::Retake), Names{});  // any press closes a page
    EXPECT_EQ(b.model().menuPage, OperatorPage::Menu);
    EXPECT_EQ(b.model().menuItem, OperatorItem::LastCodes);
    b.press(Button::Retake);
    EXPECT_EQ(b.model().menuItem, OperatorItem::FreeDisk);
    EXPECT_EQ(b.press(Button::Start), Names{"FreeDisk"});
    EXPECT_EQ(b.model().menuPage, OperatorPage::FreeDisk);
    b.press(Button::Start);
    EXPECT_EQ(b.model().menuPage, OperatorPage::Menu);
    b.press(Button::Retake);
    EXPECT_EQ(b.model().menuItem, OperatorItem::ExitMenu);
    b.press(Button::Retake);
    EXPECT_EQ(b.model().menuItem, OperatorItem::LastCodes);  // wraps around
    b.press(Button::Retake);
    b.press(Button::Retake);
    EXPECT_EQ(b.press(Button::Start), Names{kLampsAttract});
    EXPECT_EQ(b.screen(), ScreenId::Attract);
}

TEST(VisitorFlow, OperatorMenuTimesOut) {
    Booth b;
    b.toOperator();
    b.press(Button::Retake, 100.0);  // a press restarts the timeout
    const double t0 = b.now - 0.1;
    b.tickAt(t0 + 119.9);
    EXPECT_EQ(b.screen(), ScreenId::OperatorMenu);
    EXPECT_EQ(b.tickAt(t0 + 120.0), Names{kLampsAttract});
    EXPECT_EQ(b.screen(), ScreenId::Attract);
}

TEST(VisitorFlow, LockMustBeReleasedBeforeItOpensAgain) {
    Booth b;
    b.down(Button::Retake);
    b.down(Button::Start, 0.1);
    b.after(5.0);
    ASSERT_EQ(b.screen(), ScreenId::OperatorMenu);
    // Still holding both: the menu times out to attract; it does not reopen while the buttons stay down.
    b.after(120.0);
    ASSERT_EQ(b.screen(), ScreenId::Attract);
    b.after(10.0);
    EXPECT_EQ(b.screen(), ScreenId::Attract);
    b.up(Button::Start);
    b.down(Button::Start, 0.1);  // a new press: starts a session, then the lock again
    b.after(5.0);
    EXPECT_EQ(b.screen(), ScreenId::OperatorMenu);
}

TEST(VisitorFlow, SinceEnteredFollowsTheEventTime) {
    Booth b;
    b.toFrontGuide();
    b.after(2.5);
    EXPECT_EQ(b.model().sinceEntered, Millis(2600));  // entered at the press, 0.1 s before the release
}
