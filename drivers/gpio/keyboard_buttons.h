// Buttons from a keyboard (the development window's keys), and several button sources seen as one.
#pragma once

#include "drivers/gpio/buttons.h"

#include <deque>
#include <map>
#include <memory>
#include <set>

namespace avatarbooth {

// Keys mapped to buttons. The display owning the keyboard hands key events to feed(); keys do not bounce, so
// they pass undebounced. Auto-repeat (a held key pressing again and again) is folded into one press.
class KeyboardButtons final : public Buttons {
public:
    // `keys`: key name (X11 keysym name as the window reports it: "space", "Return", "r") → button name.
    // `buttons`: the names this source reports (normally the configured GPIO buttons, so keys and GPIO agree).
    KeyboardButtons(std::map<std::string, std::string> keys, std::vector<std::string> buttons);

    // One key going down or up; keys not in the map are ignored. Returns whether the key is mapped.
    bool feed(const std::string& key, bool pressed, SteadyTime time);

    std::optional<ButtonEvent> poll(std::chrono::milliseconds timeout) override;
    bool isDown(const std::string& button) const override;
    std::vector<std::string> names() const override { return buttons_; }
    std::string describe() const override;

private:
    std::map<std::string, std::string> keys_;
    std::vector<std::string> buttons_;
    std::map<std::string, std::set<std::string>> keysDown_;  // button → keys holding it down
    std::set<std::string> reportedDown_;
    std::deque<ButtonEvent> queue_;
};

// Several sources seen as one (GPIO or the sim timeline, plus the keyboard). A button is down when any source
// holds it down.
class MergedButtons final : public Buttons {
public:
    explicit MergedButtons(std::vector<std::unique_ptr<Buttons>> sources);

    // Asks every source without waiting; when none has an event, waits on the first source (the hardware or the
    // script) in slices of at most 10 ms and asks the others between slices, until `timeout`.
    std::optional<ButtonEvent> poll(std::chrono::milliseconds timeout) override;
    bool isDown(const std::string& button) const override;
    std::vector<std::string> names() const override;
    std::string describe() const override;
    // Finished when the first source is (the keyboard never is).
    bool finished() const override;

    Buttons& source(std::size_t i) { return *sources_.at(i); }

private:
    std::vector<std::unique_ptr<Buttons>> sources_;
};

}  // namespace avatarbooth
