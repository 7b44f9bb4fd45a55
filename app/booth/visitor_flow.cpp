// The visitor flow state machine (see visitor_flow.h for the states and BoothSettings for every timing).
#include "booth/visitor_flow.h"

#include <algorithm>
#include <cmath>

namespace avatarbooth {

namespace {

template <class... F>
struct Overload : F... {
    using F::operator()...;
};
template <class... F>
Overload(F...) -> Overload<F...>;

std::size_t idx(Button b) { return static_cast<std::size_t>(b); }

}  // namespace

FlowTime eventTime(const FlowEvent& event) {
    return std::visit([](const auto& e) { return e.t; }, event);
}

std::string describe(const FlowCommand& command) {
    auto photo = [](Photo p) { return p == Photo::Front ? std::string("front") : std::string("side"); };
    auto lamp = [](LampMode l) {
        switch (l) {
            case LampMode::Off: return "off";
            case LampMode::On: return "on";
            case LampMode::SlowBlink: return "slow";
            case LampMode::FastBlink: return "fast";
        }
        return "?";
    };
    return std::visit(Overload{
                          [&](const StartPreview& c) { return "StartPreview(" + photo(c.photo) + ")"; },
                          [](const StopPreview&) { return std::string("StopPreview"); },
                          [&](const CapturePhoto& c) { return "CapturePhoto(" + photo(c.photo) + ")"; },
                          [](const StartFit&) { return std::string("StartFit"); },
                          [](const CancelFit&) { return std::string("CancelFit"); },
                          [](const SaveSession&) { return std::string("SaveSession"); },
                          [](const DiscardSession&) { return std::string("DiscardSession"); },
                          [&](const SetLamps& c) {
                              return std::string("SetLamps(start=") + lamp(c.lamps.start) +
                                     ",retake=" + lamp(c.lamps.retake) + ",flash=" + lamp(c.lamps.flash) + ")";
                          },
                          [](const FreeDisk&) { return std::string("FreeDisk"); },
                      },
                      command);
}

const char* toString(ScreenId id) {
    switch (id) {
        case ScreenId::Attract: return "attract";
        case ScreenId::FrontGuide: return "front_guide";
        case ScreenId::SideGuide: return "side_guide";
        case ScreenId::Countdown: return "countdown";
        case ScreenId::CaptureFlash: return "capture_flash";
        case ScreenId::Processing: return "processing";
        case ScreenId::Reveal: return "reveal";
        case ScreenId::RetakeChoice: return "retake_choice";
        case ScreenId::Thanks: return "thanks";
        case ScreenId::CameraLost: return "camera_lost";
        case ScreenId::OperatorMenu: return "operator_menu";
    }
    return "?";
}

const char* toString(Hint hint) {
    switch (hint) {
        case Hint::None: return "none";
        case Hint::NoFace: return "no_face";
        case Hint::StepCloser: return "step_closer";
        case Hint::StepBack: return "step_back";
        case Hint::MoveToCentre: return "move_to_centre";
        case Hint::LookAtCamera: return "look_at_camera";
        case Hint::TurnRight: return "turn_right";
        case Hint::TurnMore: return "turn_more";
        case Hint::TurnBack: return "turn_back";
        case Hint::FaceHidden: return "face_hidden";
        case Hint::HoldStill: return "hold_still";
    }
    return "?";
}

const char* toString(Button button) {
    switch (button) {
        case Button::Start: return "start";
        case Button::Retake: return "retake";
        case Button::Service: return "service";
    }
    return "?";
}

std::optional<Button> parseButton(std::string_view name) {
    for (const Button b : {Button::Start, Button::Retake, Button::Service})
        if (name == toString(b)) return b;
    return std::nullopt;
}

VisitorFlow::VisitorFlow(BoothSettings settings, FlowTime start)
    : settings_(std::move(settings)), enteredAt_(start), lastSeen_(start), lastOperatorPress_(start) {
    std::vector<FlowCommand> ignored;
    enter(State::Attract, start, ignored);
}

std::vector<FlowCommand> VisitorFlow::initialCommands() const { return {SetLamps{lamps_}}; }

std::vector<FlowCommand> VisitorFlow::handle(const FlowEvent& event) {
    std::vector<FlowCommand> out;
    const FlowTime t = eventTime(event);
    advance(t, out);
    std::visit(Overload{
                   [&](const ButtonPressed& e) {
                       // A press of a button already down is a bounce the driver let through: it counts once.
                       if (down_[idx(e.button)]) return;
                       down_[idx(e.button)] = true;
                       downSince_[idx(e.button)] = e.t;
                       press(e.button, e.t, out);
                   },
                   [&](const ButtonReleased& e) {
                       // Held long enough up to this release opens the lock, however late the release is seen.
                       checkLock(e.t, out);
                       down_[idx(e.button)] = false;
                       if (std::find(settings_.lockCombo.begin(), settings_.lockCombo.end(), e.button) !=
                           settings_.lockCombo.end())
                           lockArmed_ = true;
                   },
                   [&](const Tick&) {},
                   [&](const PreviewAnalysed& e) {
                       if (state_ != State::Guide || e.photo != photo_) return;
                       screen_.hint = e.hint;
                       if (e.personSeen) lastSeen_ = e.t;
                       if (e.hint == Hint::HoldStill) {
                           if (!okSince_) okSince_ = e.t;
                       } else {
                           okSince_.reset();
                       }
                       advance(e.t, out);
                   },
                   [&](const CaptureDone& e) {
                       if (state_ != State::Capture || e.photo != photo_) return;
                       (photo_ == Photo::Front ? haveFront_ : haveSide_) = true;
                       nextAfterCapture(e.t, out);
                   },
                   [&](const CaptureFailed& e) {
                       if (state_ != State::Capture || e.photo != photo_) return;
                       bannerDetail_ = e.detail;
                       failBackToGuide(photo_ == Photo::Front ? RetakeWhich::Front : RetakeWhich::Side,
                                       BannerKind::CaptureFailed, FitFailure::Other, e.t, out);
                   },
                   [&](const FitProgress& e) {
                       if (state_ != State::Processing) return;
                       screen_.progress = progressAtStart(e.step);
                       screen_.fitStep = e.step;
                   },
                   [&](const FitDone& e) {
                       if (state_ != State::Processing) return;
                       fitRunning_ = false;
                       screen_.progress = 1.0;
                       enter(State::Reveal, e.t, out);
                   },
                   [&](const FitFailed& e) {
                       if (state_ != State::Processing) return;
                       fitRunning_ = false;
                       bannerDetail_ = e.detail;
                       failBackToGuide(e.retake, BannerKind::FitFailed, e.reason, e.t, out);
                   },
                   [&](const SessionSaved& e) {
                       if (state_ != State::Thanks) return;
                       screen_.code = e.code;
                       screen_.shareUrl = e.shareUrl;
                       if (!thanksResultAt_) thanksResultAt_ = e.t;
                   },
                   [&](const SessionSaveFailed& e) {
                       if (state_ != State::Thanks) return;
                       banner_ = BannerKind::SaveFailed;
                       bannerDetail_ = e.detail;
                       if (!thanksResultAt_) thanksResultAt_ = e.t;
                   },
                   [&](const CameraLost& e) {
                       cameraDetail_ = e.detail;
                       if (!cameraOk_) return;
                       cameraOk_ = false;
                       // The states that need the camera wait on the camera-lost screen and resume at the
                       // guide of the photo they were taking; the others carry on with a banner.
                       if (state_ == State::Guide || state_ == State::Countdown || state_ == State::Capture) {
                           setPreview(false, photo_, out);
                           enter(State::CameraLost, e.t, out);
                       } else {
                           updateLamps(out);
                       }
                   },
                   [&](const CameraBack& e) {
                       if (cameraOk_) return;
                       cameraOk_ = true;
                       cameraDetail_.clear();
                       if (state_ == State::CameraLost) toGuide(photo_, e.t, out);
                       else updateLamps(out);
                   },
               },
               event);
    checkLock(t, out);
    syncScreen(t);
    return out;
}

// Timeouts and the countdown, in the order they fall due (one state change per call is enough: every timeout
// lands in a state whose own timeouts start afresh).
void VisitorFlow::advance(FlowTime t, std::vector<FlowCommand>& out) {
    const auto in = t - enteredAt_;
    switch (state_) {
        case State::Attract: break;
        case State::Guide:
            if (t - lastSeen_ >= settings_.guideAbsentTimeout || in >= settings_.guideMaxTime) {
                toAttract(t, out);
            } else if (okSince_ && t - *okSince_ >= settings_.steadyOk) {
                enter(State::Countdown, t, out);
            }
            break;
        case State::Countdown:
            if (in >= settings_.countdown) {
                enter(State::Capture, t, out);
                out.push_back(CapturePhoto{photo_});
            }
            break;
        case State::Capture:
            if (in >= settings_.captureTimeout) {
                bannerDetail_ = "no photo from the camera";
                failBackToGuide(photo_ == Photo::Front ? RetakeWhich::Front : RetakeWhich::Side,
                                BannerKind::CaptureFailed, FitFailure::Other, t, out);
            }
            break;
        case State::Processing:
            if (in >= settings_.processingTimeout) toAttract(t, out);
            break;
        case State::Reveal:
            if (in >= settings_.revealTimeout) toAttract(t, out);
            break;
        case State::RetakeChoice:
            if (in >= settings_.retakeChoiceTimeout) enter(State::Reveal, t, out);
            break;
        case State::Thanks:
            if (thanksResultAt_ ? t - *thanksResultAt_ >= settings_.thanksTime : in >= settings_.thanksSavingLimit)
                toAttract(t, out);
            break;
        case State::CameraLost:
            if (in >= settings_.cameraLostTimeout) toAttract(t, out);
            break;
        case State::Operator:
            if (t - lastOperatorPress_ >= settings_.operatorTimeout) toAttract(t, out);
            break;
    }
}

void VisitorFlow::press(Button b, FlowTime t, std::vector<FlowCommand>& out) {
    if (state_ == State::Operator) {
        lastOperatorPress_ = t;
        if (t - enteredAt_ < settings_.pressGuard) return;
        if (screen_.menuPage != OperatorPage::Menu) {
            screen_.menuPage = OperatorPage::Menu;  // any press closes a result page
            return;
        }
        if (b == Button::Retake) {
            screen_.menuItem = static_cast<OperatorItem>((static_cast<int>(screen_.menuItem) + 1) %
                                                         kOperatorItemCount);
        } else if (b == Button::Start) {
            switch (screen_.menuItem) {
                case OperatorItem::LastCodes: screen_.menuPage = OperatorPage::LastCodes; break;
                case OperatorItem::FreeDisk:
                    out.push_back(FreeDisk{});
                    screen_.menuPage = OperatorPage::FreeDisk;
                    break;
                case OperatorItem::ExitMenu: toAttract(t, out); break;
            }
        }
        return;
    }
    if (t - enteredAt_ < settings_.pressGuard) return;
    switch (state_) {
        case State::Attract:
            if (b == Button::Start && cameraOk_) startSession(t, out);
            break;
        case State::Guide:
            if (b == Button::Start) enter(State::Countdown, t, out);
            break;
        case State::Reveal:
            if (b == Button::Start) {
                enter(State::Thanks, t, out);
                out.push_back(SaveSession{});
                sessionOpen_ = false;
            } else if (b == Button::Retake) {
                enter(State::RetakeChoice, t, out);
            }
            break;
        case State::RetakeChoice:
            if (b == Button::Start || b == Button::Retake) {
                const Photo p = b == Button::Start ? Photo::Front : Photo::Side;
                (p == Photo::Front ? haveFront_ : haveSide_) = false;
                toGuide(p, t, out);
            }
            break;
        case State::Thanks:
            if (b == Button::Start && t - enteredAt_ >= settings_.thanksMinTime && cameraOk_) startSession(t, out);
            break;
        // Countdown and capture run to their end; processing cannot be interrupted by a visitor; the camera-lost
        // screen waits for the camera.
        case State::Countdown:
        case State::Capture:
        case State::Processing:
        case State::CameraLost:
        case State::Operator: break;
    }
}

void VisitorFlow::checkLock(FlowTime t, std::vector<FlowCommand>& out) {
    if (!lockArmed_ || settings_.lockCombo.empty() || state_ == State::Operator) return;
    FlowTime latest{};
    for (int i = 0; i < kButtonCount; ++i) {
        const auto b = static_cast<Button>(i);
        const bool inCombo =
            std::find(settings_.lockCombo.begin(), settings_.lockCombo.end(), b) != settings_.lockCombo.end();
        if (down_[static_cast<std::size_t>(i)] != inCombo) return;  // a combo button up, or another one down
        if (inCombo) latest = std::max(latest, downSince_[static_cast<std::size_t>(i)]);
    }
    if (t - latest < settings_.lockHold) return;
    lockArmed_ = false;
    if (fitRunning_) {
        out.push_back(CancelFit{});
        fitRunning_ = false;
    }
    setPreview(false, photo_, out);
    discardIfOpen(out);
    banner_ = BannerKind::None;
    screen_.menuItem = OperatorItem::LastCodes;
    screen_.menuPage = OperatorPage::Menu;
    lastOperatorPress_ = t;
    enter(State::Operator, t, out);
}

void VisitorFlow::enter(State s, FlowTime t, std::vector<FlowCommand>& out) {
    state_ = s;
    enteredAt_ = t;
    okSince_.reset();
    thanksResultAt_.reset();
    if (s == State::Countdown) banner_ = BannerKind::None;  // the visitor has seen why; a new photo is coming
    if (s == State::Guide) {
        lastSeen_ = t;
        screen_.hint = Hint::None;
    }
    updateLamps(out);
}

void VisitorFlow::toAttract(FlowTime t, std::vector<FlowCommand>& out) {
    if (fitRunning_) {
        out.push_back(CancelFit{});
        fitRunning_ = false;
    }
    setPreview(false, photo_, out);
    discardIfOpen(out);
    banner_ = BannerKind::None;
    haveFront_ = haveSide_ = false;
    enter(State::Attract, t, out);
}

void VisitorFlow::startSession(FlowTime t, std::vector<FlowCommand>& out) {
    sessionOpen_ = true;
    haveFront_ = haveSide_ = false;
    banner_ = BannerKind::None;
    screen_.code.clear();
    screen_.shareUrl.clear();
    screen_.progress = 0.0;
    screen_.fitStep.reset();
    toGuide(Photo::Front, t, out);
}

void VisitorFlow::toGuide(Photo p, FlowTime t, std::vector<FlowCommand>& out) {
    photo_ = p;
    if (!cameraOk_) {
        enter(State::CameraLost, t, out);
        return;
    }
    enter(State::Guide, t, out);
    setPreview(true, p, out);
}

void VisitorFlow::nextAfterCapture(FlowTime t, std::vector<FlowCommand>& out) {
    if (!haveFront_) {
        toGuide(Photo::Front, t, out);
    } else if (!haveSide_) {
        toGuide(Photo::Side, t, out);
    } else {
        setPreview(false, photo_, out);
        screen_.progress = 0.0;
        screen_.fitStep.reset();
        enter(State::Processing, t, out);
        out.push_back(StartFit{});
        fitRunning_ = true;
    }
}

void VisitorFlow::failBackToGuide(RetakeWhich which, BannerKind banner, FitFailure reason, FlowTime t,
                                  std::vector<FlowCommand>& out) {
    if (which == RetakeWhich::Front || which == RetakeWhich::Both) haveFront_ = false;
    if (which == RetakeWhich::Side || which == RetakeWhich::Both) haveSide_ = false;
    toGuide(haveFront_ ? Photo::Side : Photo::Front, t, out);
    banner_ = banner;
    fitFailure_ = reason;
}

void VisitorFlow::discardIfOpen(std::vector<FlowCommand>& out) {
    if (!sessionOpen_) return;
    out.push_back(DiscardSession{});
    sessionOpen_ = false;
}

void VisitorFlow::setPreview(bool on, Photo p, std::vector<FlowCommand>& out) {
    if (on) {
        if (previewOn_ && previewPhoto_ == p) return;
        out.push_back(StartPreview{p});
        previewOn_ = true;
        previewPhoto_ = p;
    } else if (previewOn_) {
        out.push_back(StopPreview{});
        previewOn_ = false;
    }
}

void VisitorFlow::updateLamps(std::vector<FlowCommand>& out) {
    LampState l;
    switch (state_) {
        case State::Attract: l.start = cameraOk_ ? LampMode::SlowBlink : LampMode::Off; break;
        case State::Guide: l.start = LampMode::On; break;
        case State::Countdown: break;
        case State::Capture: l.flash = LampMode::On; break;
        case State::Processing: break;
        case State::Reveal:
        case State::RetakeChoice:
        case State::Operator: l.start = l.retake = LampMode::On; break;
        case State::Thanks: break;
        case State::CameraLost: break;
    }
    if (lampsSent_ && l == lamps_) return;
    lamps_ = l;
    lampsSent_ = true;
    out.push_back(SetLamps{l});
}

void VisitorFlow::syncScreen(FlowTime t) {
    ScreenModel& s = screen_;
    switch (state_) {
        case State::Attract: s.id = ScreenId::Attract; break;
        case State::Guide: s.id = photo_ == Photo::Front ? ScreenId::FrontGuide : ScreenId::SideGuide; break;
        case State::Countdown: s.id = ScreenId::Countdown; break;
        case State::Capture: s.id = ScreenId::CaptureFlash; break;
        case State::Processing: s.id = ScreenId::Processing; break;
        case State::Reveal: s.id = ScreenId::Reveal; break;
        case State::RetakeChoice: s.id = ScreenId::RetakeChoice; break;
        case State::Thanks: s.id = ScreenId::Thanks; break;
        case State::CameraLost: s.id = ScreenId::CameraLost; break;
        case State::Operator: s.id = ScreenId::OperatorMenu; break;
    }
    s.sinceEntered = std::chrono::duration_cast<Millis>(t - enteredAt_);
    s.photo = photo_;
    s.cameraAvailable = cameraOk_;
    if (state_ != State::Guide) s.hint = Hint::None;
    if (state_ == State::Countdown) {
        const auto left = settings_.countdown - s.sinceEntered;
        s.countdown = static_cast<int>(std::max<long long>(1, (left.count() + 999) / 1000));
        s.countdownAge = s.sinceEntered - std::max(Millis(0), settings_.countdown - Millis(1000) * s.countdown);
    } else {
        s.countdown = 0;
        s.countdownAge = Millis(0);
    }
    // A lost camera outranks every other message; the operator menu shows the camera's state on its own.
    if (!cameraOk_ && state_ != State::Operator) {
        s.banner = BannerKind::CameraLost;
        s.detail = cameraDetail_;
    } else if (state_ == State::Operator) {
        s.banner = BannerKind::None;
        s.detail.clear();
    } else {
        s.banner = banner_;
        s.detail = banner_ == BannerKind::None ? std::string() : bannerDetail_;
    }
    s.fitFailure = fitFailure_;
    if (state_ != State::Operator) {
        s.menuItem = OperatorItem::LastCodes;
        s.menuPage = OperatorPage::Menu;
    }
}

}  // namespace avatarbooth
