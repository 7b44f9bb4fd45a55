// Keyboard keys as buttons, and merging of button sources.
#include "drivers/gpio/keyboard_buttons.h"

#include "common/error.h"

#include <algorithm>

namespace avatarbooth {

KeyboardButtons::KeyboardButtons(std::map<std::string, std::string> keys, std::vector<std::string> buttons)
    : keys_(std::move(keys)), buttons_(std::move(buttons)) {
    for (const auto& [key, button] : keys_)
        if (std::find(buttons_.begin(), buttons_.end(), button) == buttons_.end())
            throw BoothError(ErrorKind::BadConfig, "key \"" + key + "\"",
                             "is mapped to the unknown button \"" + button + "\"");
}

bool KeyboardButtons::feed(const std::string& key, bool pressed, SteadyTime time) {
    const auto it = keys_.find(key);
    if (it == keys_.end()) return false;
    const std::string& button = it->second;
    auto& holders = keysDown_[button];
    // The button is down while any key mapped to it is; a repeated press of a held key changes nothing.
    const bool wasDown = !holders.empty();
    if (pressed) holders.insert(key);
    else holders.erase(key);
    const bool isNowDown = !holders.empty();
    if (isNowDown != wasDown)
        queue_.push_back({button, isNowDown ? ButtonAction::Press : ButtonAction::Release, time});
    return true;
}

std::optional<ButtonEvent> KeyboardButtons::poll(std::chrono::milliseconds) {
    // Keys arrive through feed() from the same thread, so there is nothing to wait for here.
    if (queue_.empty()) return std::nullopt;
    ButtonEvent e = std::move(queue_.front());
    queue_.pop_front();
    if (e.action == ButtonAction::Press) reportedDown_.insert(e.button);
    else reportedDown_.erase(e.button);
    return e;
}

bool KeyboardButtons::isDown(const std::string& button) const { return reportedDown_.count(button) > 0; }

std::string KeyboardButtons::describe() const {
    std::string s = "keyboard:";
    for (const auto& [key, button] : keys_) s += " " + key + "=" + button;
    return s;
}

MergedButtons::MergedButtons(std::vector<std::unique_ptr<Buttons>> sources) : sources_(std::move(sources)) {
    if (sources_.empty()) throw BoothError(ErrorKind::Internal, "buttons", "no button source to merge");
}

std::optional<ButtonEvent> MergedButtons::poll(std::chrono::milliseconds timeout) {
    using std::chrono::milliseconds;
    milliseconds left = std::max(timeout, milliseconds::zero());
    for (;;) {
        for (auto& s : sources_)
            if (auto e = s->poll(milliseconds::zero())) return e;
        if (left <= milliseconds::zero()) return std::nullopt;
        const milliseconds slice = sources_.size() == 1 ? left : std::min(left, milliseconds(10));
        if (auto e = sources_.front()->poll(slice)) return e;
        left -= slice;
    }
}

bool MergedButtons::isDown(const std::string& button) const {
    return std::any_of(sources_.begin(), sources_.end(), [&](const auto& s) { return s->isDown(button); });
}

std::vector<std::string> MergedButtons::names() const {
    std::vector<std::string> out;
    for (const auto& s : sources_)
        for (auto& n : s->names())
            if (std::find(out.begin(), out.end(), n) == out.end()) out.push_back(std::move(n));
    return out;
}

std::string MergedButtons::describe() const {
    std::string s;
    for (const auto& src : sources_) s += (s.empty() ? "" : " + ") + src->describe();
    return s;
}

bool MergedButtons::finished() const { return sources_.front()->finished(); }

}  // namespace avatarbooth
