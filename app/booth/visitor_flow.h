// The kiosk's visitor flow as a state machine: attract -> front guide -> countdown -> capture -> side guide ->
// countdown -> capture -> processing -> reveal -> keep (thanks) or retake, with timeouts, failure paths, a lost
// camera and the operator menu. Plain logic: events in (with their time), commands and a screen model out; it
// never reads a clock, a device or a file, so every path is testable from a list of events.
#pragma once

#include "booth/flow_types.h"

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace avatarbooth {

struct BoothSettings {
    // Countdown before each photo; the screen shows whole seconds (3, 2, 1).
    Millis countdown{3000};
    // The guide's hint must say "hold still" this long without a break before the countdown starts by itself
    // (the Start button starts it at once).
    Millis steadyOk{1000};
    // A guide goes back to attract when nobody has been seen in the preview for this long (walked away) ...
    Millis guideAbsentTimeout{20000};
    // ... and after this long in any case (someone who never gets a "hold still" and never presses Start).
    Millis guideMaxTime{120000};
    // No photo from the camera this long after the capture command: the capture failed (back to the guide).
    Millis captureTimeout{10000};
    // A fit still running after this long is cancelled and the visitor's session discarded.
    Millis processingTimeout{90000};
    // The reveal waits this long for keep or retake; then the session is discarded (never kept unasked).
    Millis revealTimeout{60000};
    // The "which photo?" question goes back to the reveal after this long.
    Millis retakeChoiceTimeout{20000};
    // The thanks screen shows the session's code (or that it could not be saved) this long, counted from when the
    // code is known ...
    Millis thanksTime{20000};
    // ... and ignores the Start button for this long, so the code is not skipped by an eager next visitor.
    Millis thanksMinTime{5000};
    // While the kept session is still being written (a slow card) the thanks screen says "saving" and waits for
    // the code, but at most this long; then the booth goes back to attract (the write goes on, its result logged).
    Millis thanksSavingLimit{120000};
    // With the camera lost in the middle of a session, the session is given up after this long.
    Millis cameraLostTimeout{60000};
    // Presses within this long of a screen change are ignored, so a double press does not also act on the
    // next screen (the drivers already debounce each press edge).
    Millis pressGuard{500};
    // The operator lock: exactly these buttons held together for lockHold opens the operator menu, from any
    // screen (a session in progress is discarded). Guests hold buttons rarely for 5 s; a booth with a Service
    // button inside the cabinet can use {Service} alone.
    std::vector<Button> lockCombo{Button::Start, Button::Retake};
    Millis lockHold{5000};
    // The operator menu closes after this long without a press.
    Millis operatorTimeout{120000};
};

class VisitorFlow {
public:
    // Starts on the attract screen at time `start`. Call initialCommands() once for the lamps.
    explicit VisitorFlow(BoothSettings settings, FlowTime start);

    // The commands to put the devices in the attract state (lamps).
    std::vector<FlowCommand> initialCommands() const;

    // Applies timeouts up to the event's time, then the event. Returns the commands for the kiosk, in order.
    std::vector<FlowCommand> handle(const FlowEvent& event);

    const ScreenModel& screen() const { return screen_; }
    const BoothSettings& settings() const { return settings_; }

private:
    enum class State { Attract, Guide, Countdown, Capture, Processing, Reveal, RetakeChoice, Thanks, CameraLost,
                       Operator };

    void advance(FlowTime t, std::vector<FlowCommand>& out);
    void press(Button b, FlowTime t, std::vector<FlowCommand>& out);
    void checkLock(FlowTime t, std::vector<FlowCommand>& out);

    void enter(State s, FlowTime t, std::vector<FlowCommand>& out);
    void toAttract(FlowTime t, std::vector<FlowCommand>& out);
    void startSession(FlowTime t, std::vector<FlowCommand>& out);
    void toGuide(Photo p, FlowTime t, std::vector<FlowCommand>& out);
    void nextAfterCapture(FlowTime t, std::vector<FlowCommand>& out);
    void failBackToGuide(RetakeWhich which, BannerKind banner, FitFailure reason, FlowTime t,
                         std::vector<FlowCommand>& out);
    void discardIfOpen(std::vector<FlowCommand>& out);
    void setPreview(bool on, Photo p, std::vector<FlowCommand>& out);
    void updateLamps(std::vector<FlowCommand>& out);
    void syncScreen(FlowTime t);

    BoothSettings settings_;
    State state_ = State::Attract;
    FlowTime enteredAt_;
    std::optional<FlowTime> thanksResultAt_;  // thanks: when the code or the save's failure became known
    FlowTime lastSeen_;                    // guides: last preview with a person (or the guide's start)
    std::optional<FlowTime> okSince_;      // guides: start of the current run of "hold still"
    FlowTime lastOperatorPress_;
    Photo photo_ = Photo::Front;           // guide/countdown/capture/camera-lost: the photo being taken
    bool haveFront_ = false, haveSide_ = false;  // photos of this session that stand (not to be retaken)
    bool sessionOpen_ = false;             // a session exists that is neither saved nor discarded
    bool previewOn_ = false;
    Photo previewPhoto_ = Photo::Front;
    bool fitRunning_ = false;
    bool cameraOk_ = true;
    std::string cameraDetail_;             // why the camera is lost
    BannerKind banner_ = BannerKind::None; // the last failure, shown until the next countdown
    FitFailure fitFailure_ = FitFailure::Other;
    std::string bannerDetail_;
    std::array<bool, kButtonCount> down_{};
    std::array<FlowTime, kButtonCount> downSince_{};
    bool lockArmed_ = true;                // re-armed once a lock button is released
    LampState lamps_;
    bool lampsSent_ = false;
    ScreenModel screen_;
};

}  // namespace avatarbooth
