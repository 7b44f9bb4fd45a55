// The flow and the screens together, as the kiosk will use them: a scripted visitor session (with a failed fit, a
// retake and a lost camera) drives VisitorFlow, and every model it produces is drawn by ScreenRenderer. Writes the
// sequence as PNGs (tests/work/screens_flow/) and checks that each screen of a session is reached and drawn.
#include "booth/visitor_flow.h"
#include "booth/screens/screens.h"
#include "test_paths.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <gtest/gtest.h>

#include <set>

using namespace avatarbooth;

TEST(ScreensFlow, ScriptedSessionDrawsEveryScreen) {
    const auto dir = test::scratchDir("screens_flow");
    ScreenRenderer screens(ScreenSettings{});
    VisitorFlow flow(BoothSettings{}, FlowTime{});

    // A camera frame with a face-sized bright ellipse in the oval, and a blue "avatar".
    cv::Mat frame(480, 640, CV_8UC3, cv::Scalar(60, 40, 30));
    cv::ellipse(frame, {320, 250}, {90, 120}, 0, 0, 360, cv::Scalar(150, 180, 220), cv::FILLED);
    ScreenInputs in;
    in.preview = frame;
    in.avatar = cv::Mat(300, 300, CV_8UC3, cv::Scalar(200, 80, 20));

    double t = 0.0;
    int step = 0;
    std::set<ScreenId> seen;
    std::vector<std::string> commands;
    cv::Mat last;
    auto at = [](double s) {
        return FlowTime{} + std::chrono::round<FlowClock::duration>(std::chrono::duration<double>(s));
    };
    auto send = [&](const FlowEvent& e) {
        t = std::chrono::duration<double>(eventTime(e) - FlowTime{}).count();
        for (const auto& c : flow.handle(e)) commands.push_back(describe(c));
        const cv::Mat& img = screens.draw(flow.screen(), in);
        ASSERT_EQ(img.size(), cv::Size(1280, 720));
        cv::imwrite((dir / cv::format("%02d_%s.png", step++, toString(flow.screen().id))).string(), img);
        seen.insert(flow.screen().id);
        last = img.clone();
    };
    auto press = [&](Button b, double dt = 1.0) {
        send(ButtonPressed{b, at(t + dt)});
        send(ButtonReleased{b, at(t + 0.1)});
    };

    press(Button::Start);                                              // attract -> front guide
    send(PreviewAnalysed{Photo::Front, Hint::StepCloser, true, at(t + 0.1)});
    send(PreviewAnalysed{Photo::Front, Hint::HoldStill, true, at(t + 0.5)});
    send(Tick{at(t + 1.0)});                                           // -> countdown
    send(Tick{at(t + 1.5)});
    send(Tick{at(t + 2.5)});                                           // -> capture
    send(CaptureDone{Photo::Front, at(t + 0.2)});                      // -> side guide
    send(CameraLost{"/dev/video0: No such device", at(t + 0.5)});      // -> camera lost
    send(CameraBack{at(t + 3.0)});                                     // -> side guide
    send(PreviewAnalysed{Photo::Side, Hint::TurnMore, true, at(t + 0.1)});
    press(Button::Start);                                              // -> countdown
    send(Tick{at(t + 3.0)});                                           // -> capture
    send(CaptureDone{Photo::Side, at(t + 0.2)});                       // -> processing
    send(FitProgress{FitStep::FrontLandmarks, at(t + 0.3)});
    send(FitFailed{RetakeWhich::Side, FitFailure::NotProfile, "side.jpg: a front view", at(t + 0.3)});
    press(Button::Start);                                              // side guide -> countdown
    send(Tick{at(t + 3.0)});
    send(CaptureDone{Photo::Side, at(t + 0.2)});                       // -> processing
    send(FitProgress{FitStep::Texture, at(t + 0.5)});
    send(FitDone{at(t + 0.5)});                                        // -> reveal
    press(Button::Retake);                                             // -> retake choice
    send(Tick{at(t + 20.0)});                                          // -> reveal again
    press(Button::Start);                                              // keep -> thanks
    send(SessionSaved{"AB3K7Z", at(t + 0.2)});
    send(Tick{at(t + 20.0)});                                          // -> attract
    send(ButtonPressed{Button::Retake, at(t + 1.0)});                  // the operator's lock
    send(ButtonPressed{Button::Start, at(t + 0.1)});
    send(Tick{at(t + 5.0)});                                           // -> operator menu

    const std::set<ScreenId> expected{ScreenId::Attract,   ScreenId::FrontGuide,  ScreenId::Countdown,
                                      ScreenId::CaptureFlash, ScreenId::SideGuide, ScreenId::CameraLost,
                                      ScreenId::Processing, ScreenId::Reveal,     ScreenId::RetakeChoice,
                                      ScreenId::Thanks,     ScreenId::OperatorMenu};
    EXPECT_EQ(seen, expected);
    EXPECT_EQ(flow.screen().id, ScreenId::OperatorMenu);
    // The kiosk was asked for the front photo once, the side one twice (the fit failed once), two fits, one save.
    EXPECT_EQ(std::count(commands.begin(), commands.end(), "CapturePhoto(front)"), 1);
    EXPECT_EQ(std::count(commands.begin(), commands.end(), "CapturePhoto(side)"), 2);
    EXPECT_EQ(std::count(commands.begin(), commands.end(), "StartFit"), 2);
    EXPECT_EQ(std::count(commands.begin(), commands.end(), "SaveSession"), 1);
    EXPECT_EQ(std::count(commands.begin(), commands.end(), "DiscardSession"), 1);  // the session the lock opened
    EXPECT_FALSE(last.empty());
}
