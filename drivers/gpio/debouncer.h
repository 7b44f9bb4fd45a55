// Debouncing of one button line: raw edges in, clean press/release transitions out. Pure logic, time injected.
#pragma once

#include "common/clock.h"

#include <chrono>
#include <optional>
#include <vector>

namespace avatarbooth {

struct DebounceSettings {
    // Two changes of the reported state are never closer than this; the contacts of an arcade button bounce
    // for 1-10 ms. Operators complain about buttons that react late, so keep it at or under 50 ms.
    std::chrono::nanoseconds period = std::chrono::milliseconds(30);
    // The line reads low while the button is pressed (a button to ground with a pull-up: the usual wiring).
    bool activeLow = true;
};

// One confirmed change of the button: pressed or released, and when.
struct ButtonTransition {
    bool pressed = false;
    SteadyTime time;

    bool operator==(const ButtonTransition&) const = default;
};

// The rule: the reported state follows the line, but never changes twice within `period`. A change of the line
// is reported at once (on the edge: the press needs no hold) when the last reported change is at least `period`
// ago; otherwise it is reported when `period` has passed since the last reported change, if the line still
// differs then, stamped with that instant. So a burst of bounces after an edge counts as that one edge, a tap
// shorter than `period` still gives a press and a release, and the result does not depend on when advance() is
// called.
class Debouncer {
public:
    // `levelHigh`: the line's level when watching starts (a button held then counts as down, without a press).
    Debouncer(DebounceSettings settings, bool levelHigh, SteadyTime start);

    // Feeds one edge: the line's level after it, at time t (edges must come in time order; an earlier t is taken
    // as the previous one). Returns the transitions confirmed up to and including t (none, one or two: a change
    // waiting since an earlier edge, then this one).
    std::vector<ButtonTransition> edge(bool levelHigh, SteadyTime t);
    // Lets time pass without an edge; returns the waiting change if `now` reaches its confirmation time.
    std::optional<ButtonTransition> advance(SteadyTime now);
    // When advance() will confirm a waiting change; nullopt when the line agrees with the reported state.
    std::optional<SteadyTime> pendingUntil() const;
    // The reported (debounced) state.
    bool pressed() const { return pressed_; }

private:
    bool isPressedLevel(bool levelHigh) const { return settings_.activeLow ? !levelHigh : levelHigh; }

    DebounceSettings settings_;
    bool pressed_ = false;  // reported state
    bool raw_ = false;      // the line's latest state, as pressed/not pressed
    SteadyTime lastChange_;  // time of the last reported change (start - period at first: the first edge counts)
    SteadyTime lastEdge_;
};

}  // namespace avatarbooth
