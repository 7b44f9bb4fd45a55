// Buttons: press and release events from arcade buttons (GPIO), a scripted timeline (sim) or a keyboard.
#pragma once

#include "common/clock.h"

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace avatarbooth {

enum class ButtonAction { Press, Release };

// One debounced change of a button. A press is reported on its edge: nobody has to hold a button for it to count.
struct ButtonEvent {
    std::string button;  // the configured name, e.g. "start" or "retake"
    ButtonAction action = ButtonAction::Press;
    SteadyTime time;     // when the change happened (the edge, or the end of the debounce window that confirmed it)

    bool operator==(const ButtonEvent&) const = default;
};

// A source of button events. Single-threaded: the kiosk's main loop calls poll() (with a zero timeout once per
// frame, or a longer one when idle).
class Buttons {
public:
    virtual ~Buttons() = default;
    // Waits up to `timeout` for the next press or release and returns it; nullopt when none came in that time.
    // Events come out in time order per source. A zero timeout only collects what has already happened.
    virtual std::optional<ButtonEvent> poll(std::chrono::milliseconds timeout) = 0;
    // Whether `button` is held down, as told by the events poll() has returned so far (false for unknown names).
    virtual bool isDown(const std::string& button) const = 0;
    // The buttons this source reports, in configured order.
    virtual std::vector<std::string> names() const = 0;
    // One line for the start-up log, e.g. "gpiod gpiochip0 [pinctrl-bcm2711]: start=17 retake=27, debounce 30 ms".
    virtual std::string describe() const = 0;
    // True when the source will never report anything again (a scripted timeline that has run out).
    virtual bool finished() const { return false; }
};

// Recognises a combination of buttons held together for a while: the operator's lock, so guests cannot open the
// settings by pressing one button. Fed with the events of a Buttons source; pure logic, time given by the caller.
class HoldDetector {
public:
    HoldDetector(std::vector<std::string> combination, std::chrono::nanoseconds holdFor);
    // Follows one event (events of other buttons are ignored).
    void observe(const ButtonEvent& event);
    // True once, at the first call at or after the moment every button of the combination has been down for
    // `holdFor` (counted from the last of them going down); re-armed when any of them is released.
    bool fired(SteadyTime now);
    // When fired() will turn true if nothing is released before; nullopt while the combination is not held or
    // after it fired.
    std::optional<SteadyTime> due() const;

private:
    std::vector<std::string> combination_;
    std::chrono::nanoseconds holdFor_;
    std::vector<bool> down_;
    SteadyTime allDownSince_{};
    bool allDown_ = false;
    bool firedThisHold_ = false;
};

}  // namespace avatarbooth
