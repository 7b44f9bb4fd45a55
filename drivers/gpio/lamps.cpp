// Lamps on GPIO lines or simulated, and lamp patterns evaluated in time.
#include "drivers/gpio/lamps.h"

#include "common/error.h"

#include <algorithm>

namespace avatarbooth {
namespace {

[[noreturn]] void unknownLamp(const std::string& name, const std::vector<std::string>& names) {
    std::string known;
    for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
    throw BoothError(ErrorKind::BadConfig, "lamp \"" + name + "\"", "no such lamp (lamps: " + known + ")");
}

}  // namespace

LineLamps::LineLamps(std::unique_ptr<RawOutputLines> lines, std::vector<std::string> names,
                     std::vector<bool> activeLow)
    : lines_(std::move(lines)), names_(std::move(names)), activeLow_(std::move(activeLow)), on_(names_.size()) {
    activeLow_.resize(names_.size(), false);
    for (std::size_t i = 0; i < names_.size(); ++i) lines_->set(i, activeLow_[i]);
}

std::size_t LineLamps::index(const std::string& name) const {
    const auto it = std::find(names_.begin(), names_.end(), name);
    if (it == names_.end()) unknownLamp(name, names_);
    return static_cast<std::size_t>(it - names_.begin());
}

void LineLamps::set(const std::string& name, bool on) {
    const std::size_t i = index(name);
    lines_->set(i, on != activeLow_[i]);
    on_[i] = on;
}

bool LineLamps::isOn(const std::string& name) const { return on_[index(name)]; }

SimLamps::SimLamps(std::vector<std::string> names, const Clock& clock) : names_(std::move(names)), clock_(clock) {
    for (const auto& n : names_) on_[n] = false;
}

void SimLamps::set(const std::string& name, bool on) {
    const auto it = on_.find(name);
    if (it == on_.end()) unknownLamp(name, names_);
    if (it->second == on) return;
    it->second = on;
    if (changes_.size() == kKeptChanges)
        changes_.erase(changes_.begin(), changes_.begin() + static_cast<std::ptrdiff_t>(kKeptChanges / 2));
    changes_.push_back({name, on, clock_.now()});
}

bool SimLamps::isOn(const std::string& name) const {
    const auto it = on_.find(name);
    if (it == on_.end()) unknownLamp(name, names_);
    return it->second;
}

LampPattern LampPattern::off() { return {}; }

LampPattern LampPattern::steady() {
    LampPattern p;
    p.kind_ = Kind::Steady;
    return p;
}

LampPattern LampPattern::blink(std::chrono::nanoseconds period, SteadyTime start, double onFraction) {
    if (period <= std::chrono::nanoseconds::zero())
        throw BoothError(ErrorKind::BadConfig, "lamp blink", "the period must be longer than 0");
    LampPattern p;
    p.kind_ = Kind::Blink;
    p.period_ = period;
    p.start_ = start;
    const double fraction = std::clamp(onFraction, 0.0, 1.0);
    p.onTime_ = std::chrono::nanoseconds(static_cast<long long>(static_cast<double>(period.count()) * fraction));
    return p;
}

LampPattern LampPattern::flash(std::chrono::nanoseconds pulse, SteadyTime start) {
    LampPattern p;
    p.kind_ = Kind::Flash;
    p.period_ = std::max(pulse, std::chrono::nanoseconds::zero());
    p.start_ = start;
    return p;
}

bool LampPattern::isOn(SteadyTime t) const {
    switch (kind_) {
        case Kind::Off: return false;
        case Kind::Steady: return true;
        case Kind::Flash: return t >= start_ && t < start_ + period_;
        case Kind::Blink:
            if (t < start_) return false;
            return (t - start_) % period_ < onTime_;
    }
    return false;
}

std::optional<SteadyTime> LampPattern::nextChange(SteadyTime t) const {
    switch (kind_) {
        case Kind::Off:
        case Kind::Steady: return std::nullopt;
        case Kind::Flash:
            if (period_ == std::chrono::nanoseconds::zero()) return std::nullopt;
            if (t < start_) return start_;
            if (t < start_ + period_) return start_ + period_;
            return std::nullopt;
        case Kind::Blink: {
            if (onTime_ == std::chrono::nanoseconds::zero() || onTime_ == period_)
                return t < start_ && onTime_ > std::chrono::nanoseconds::zero() ? std::optional(start_) : std::nullopt;
            if (t < start_) return start_;
            const auto into = (t - start_) % period_;
            const SteadyTime periodStart = t - into;
            return into < onTime_ ? periodStart + onTime_ : periodStart + period_;
        }
    }
    return std::nullopt;
}

void LampDriver::setPattern(const std::string& name, LampPattern pattern) {
    const auto names = lamps_.names();
    if (std::find(names.begin(), names.end(), name) == names.end()) unknownLamp(name, names);
    patterns_[name] = pattern;
}

void LampDriver::update(SteadyTime now) {
    for (const auto& [name, pattern] : patterns_) {
        const bool on = pattern.isOn(now);
        if (lamps_.isOn(name) != on) lamps_.set(name, on);
    }
}

std::optional<SteadyTime> LampDriver::nextChange(SteadyTime now) const {
    std::optional<SteadyTime> best;
    for (const auto& [name, pattern] : patterns_)
        if (auto t = pattern.nextChange(now); t && (!best || *t < *best)) best = t;
    return best;
}

bool LampDriver::has(const std::string& name) const {
    const auto names = lamps_.names();
    return std::find(names.begin(), names.end(), name) != names.end();
}

void showAttractLamps(LampDriver& driver, SteadyTime now, std::chrono::nanoseconds period) {
    for (const auto& name : driver.lampNames())
        driver.setPattern(name, name == "start" ? LampPattern::blink(period, now) : LampPattern::off());
}

void flashForCapture(LampDriver& driver, SteadyTime now, std::chrono::nanoseconds pulse) {
    if (driver.has("flash")) driver.setPattern("flash", LampPattern::flash(pulse, now));
}

}  // namespace avatarbooth
