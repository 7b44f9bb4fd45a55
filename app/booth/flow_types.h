// The vocabulary of the visitor flow: buttons, photos, hints, the events the kiosk feeds in, the commands it gets
// back, and the model of the screen to show. Plain values, so the flow, the screens and the kiosk share no code.
#pragma once

#include "fit/fit_step.h"

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace avatarbooth {

// Time as the kiosk's monotonic clock (std::chrono::steady_clock) reads it; tests use any epoch.
using FlowClock = std::chrono::steady_clock;
using FlowTime = FlowClock::time_point;
using Millis = std::chrono::milliseconds;

// The booth's buttons as the visitor sees them. Start is also "keep" and "front photo"; Retake is also "side
// photo" and "next item" in the operator menu. Service is an optional button inside the cabinet (none on the
// default wiring) that a lock combination may use instead of the visitor's two.
enum class Button { Start, Retake, Service };
inline constexpr int kButtonCount = 3;

enum class Photo { Front, Side };

// What the guide tells the visitor, from one analysed preview frame (see guidance.h). HoldStill is the one that
// means "ready": the flow starts the countdown when it has lasted BoothSettings::steadyOk.
enum class Hint {
    None,          // nothing analysed yet
    NoFace,        // front: no face in the preview
    StepCloser,    // front: the face is small in the oval
    StepBack,      // front: the face overflows the oval
    MoveToCentre,  // front: the face is off the oval's centre
    LookAtCamera,  // front: the face is turned or tilted
    TurnRight,     // side: a frontal face (or nobody) is seen
    TurnMore,      // side: turned, but not far enough for a profile
    TurnBack,      // side: turned past the profile (the back of the head shows more than the face)
    FaceHidden,    // side: no face shows (turned well past the profile, or hair hides it): turn a little back
    HoldStill,     // ready (front or side)
};

// Why a fit failed, as the visitor is told; the detail (the library's English message) goes to the log.
enum class FitFailure {
    NoFace,       // no face found in the photo
    NotProfile,   // the side photo is not a profile (a front view)
    TurnMore,     // the side photo is turned, but not far enough for a profile
    TurnBack,     // the side photo is turned past the profile
    FaceHidden,   // no face shows on the side photo (turned well past the profile, or hair hides it)
    Mismatch,     // the two photos do not belong together
    Other,        // anything else (internal error, disk full, ...)
};

// Which photo a failed fit asks to take again.
enum class RetakeWhich { Front, Side, Both };

// ------------------------------------------------------------------------------------------------------ events

struct ButtonPressed {
    Button button;
    FlowTime t;
};
struct ButtonReleased {
    Button button;
    FlowTime t;
};
// Sent by the kiosk's main loop (at least a few times a second) so that timeouts and the countdown advance.
struct Tick {
    FlowTime t;
};
// One analysed preview frame during a guide (the kiosk runs guidance.h on the frames it shows).
struct PreviewAnalysed {
    Photo photo;       // which guide the analysis was made for (ignored when it is not the current one)
    Hint hint;
    bool personSeen;   // someone stands in front of the camera (resets the walked-away timeout)
    FlowTime t;
};
struct CaptureDone {
    Photo photo;
    FlowTime t;
};
struct CaptureFailed {
    Photo photo;
    std::string detail;
    FlowTime t;
};
// The fit has started a step (its share of the progress bar is fit_step.h's).
struct FitProgress {
    FitStep step;
    FlowTime t;
};
struct FitDone {
    FlowTime t;
};
struct FitFailed {
    RetakeWhich retake;
    FitFailure reason;
    std::string detail;
    FlowTime t;
};
struct SessionSaved {
    std::string code;
    FlowTime t;
    std::string shareUrl{};  // the visitor's page (booth/share_link.h); empty when sharing is off
};
struct SessionSaveFailed {
    std::string detail;
    FlowTime t;
};
struct CameraLost {
    std::string detail;
    FlowTime t;
};
struct CameraBack {
    FlowTime t;
};

using FlowEvent = std::variant<ButtonPressed, ButtonReleased, Tick, PreviewAnalysed, CaptureDone, CaptureFailed,
                               FitProgress, FitDone, FitFailed, SessionSaved, SessionSaveFailed, CameraLost,
                               CameraBack>;

FlowTime eventTime(const FlowEvent& event);

// ---------------------------------------------------------------------------------------------------- commands

enum class LampMode { Off, On, SlowBlink, FastBlink };

// Every lamp's pattern; the flow sends the whole set whenever one changes.
struct LampState {
    LampMode start = LampMode::Off;
    LampMode retake = LampMode::Off;
    LampMode flash = LampMode::Off;  // the photo flash / fill light
    bool operator==(const LampState&) const = default;
};

// Run the camera's preview stream and analyse its frames for this guide.
struct StartPreview {
    Photo photo;
    bool operator==(const StartPreview&) const = default;
};
struct StopPreview {
    bool operator==(const StopPreview&) const = default;
};
// Take the still photo now (the flash lamp is already on).
struct CapturePhoto {
    Photo photo;
    bool operator==(const CapturePhoto&) const = default;
};
// Fit the last front and side photos taken (either may be a retake).
struct StartFit {
    bool operator==(const StartFit&) const = default;
};
struct CancelFit {
    bool operator==(const CancelFit&) const = default;
};
// Keep the fitted session: the kiosk stores it (session_store.h) and answers SessionSaved / SessionSaveFailed.
struct SaveSession {
    bool operator==(const SaveSession&) const = default;
};
// Forget the current visitor's photos and fit: nothing of them may remain.
struct DiscardSession {
    bool operator==(const DiscardSession&) const = default;
};
struct SetLamps {
    LampState lamps;
    bool operator==(const SetLamps&) const = default;
};
// Operator: apply retention now and remove leftovers (SessionStore::applyRetention, removeLeftovers).
struct FreeDisk {
    bool operator==(const FreeDisk&) const = default;
};

using FlowCommand = std::variant<StartPreview, StopPreview, CapturePhoto, StartFit, CancelFit, SaveSession,
                                 DiscardSession, SetLamps, FreeDisk>;

// "CapturePhoto(side)", for logs and test messages.
std::string describe(const FlowCommand& command);

// ------------------------------------------------------------------------------------------------ screen model

enum class ScreenId {
    Attract,
    FrontGuide,
    SideGuide,
    Countdown,
    CaptureFlash,
    Processing,
    Reveal,
    RetakeChoice,
    Thanks,
    CameraLost,
    OperatorMenu,
};

// A message over the screen: what went wrong (the visitor is told in their language; the detail is for the log).
enum class BannerKind { None, CameraLost, CaptureFailed, FitFailed, SaveFailed };

enum class OperatorItem { LastCodes, FreeDisk, ExitMenu };
inline constexpr int kOperatorItemCount = 3;
// Which operator page is open: the item list, or the result of an item.
enum class OperatorPage { Menu, LastCodes, FreeDisk };

// Everything a screen needs from the flow; images and operator figures come with ScreenInputs (screens.h).
struct ScreenModel {
    ScreenId id = ScreenId::Attract;
    Millis sinceEntered{0};          // time in this screen (for blinking and animations)
    Photo photo = Photo::Front;      // guide, countdown, capture: which photo
    Hint hint = Hint::None;          // guides
    int countdown = 0;               // countdown: the number shown (3, 2, 1), a new one every second
    Millis countdownAge{0};          // countdown: time since the number shown came up
    double progress = 0.0;           // processing: 0..1
    std::optional<FitStep> fitStep;  // processing: the step the fit is in (none before the first)
    std::string code;                // thanks: the session's short code (empty while saving)
    std::string shareUrl;            // thanks: the visitor's page, shown as a QR code (empty: sharing is off)
    BannerKind banner = BannerKind::None;
    FitFailure fitFailure = FitFailure::Other;  // with BannerKind::FitFailed
    std::string detail;              // the banner's technical detail (shown small on the camera-lost screen)
    bool cameraAvailable = true;
    OperatorItem menuItem = OperatorItem::LastCodes;
    OperatorPage menuPage = OperatorPage::Menu;
    bool operator==(const ScreenModel&) const = default;
};

const char* toString(ScreenId id);
// The screens that guide the visitor to a photo (the live preview with its hints).
inline bool isGuide(ScreenId s) { return s == ScreenId::FrontGuide || s == ScreenId::SideGuide; }
const char* toString(Hint hint);
const char* toString(Button button);
// The button toString names ("start", "retake", "service"); nothing for any other word. The one mapping from the
// names in config files, key bindings and button events to Button.
std::optional<Button> parseButton(std::string_view name);

}  // namespace avatarbooth
