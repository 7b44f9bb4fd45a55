// Parsing scripted button timelines and replaying them as input lines.
#include "drivers/gpio/button_timeline.h"

#include "common/error.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

namespace avatarbooth {
namespace {

using std::chrono::nanoseconds;

constexpr nanoseconds kDefaultTap = std::chrono::milliseconds(100);
constexpr nanoseconds kBounceStep = std::chrono::milliseconds(1);
constexpr int kMaxBounces = 50;

std::string formatTime(nanoseconds t) {
    std::ostringstream s;
    s << static_cast<double>(t.count()) / 1e9 << "s";
    return s.str();
}

class LineParser {
public:
    LineParser(const std::string& source, int line) : where_(source + ":" + std::to_string(line)) {}

    [[noreturn]] void fail(const std::string& what) const { throw BoothError(ErrorKind::BadConfig, where_, what); }

    // "2.5s", "300ms", "1min" → nanoseconds.
    nanoseconds time(std::string_view word, const char* what) const {
        std::size_t digits = 0;
        while (digits < word.size() && (std::isdigit(static_cast<unsigned char>(word[digits])) || word[digits] == '.'))
            ++digits;
        const std::string_view number = word.substr(0, digits), unit = word.substr(digits);
        double value = 0;
        const auto [end, ec] = std::from_chars(number.data(), number.data() + number.size(), value);
        if (number.empty() || ec != std::errc() || end != number.data() + number.size())
            fail(std::string(what) + " \"" + std::string(word) + "\" is not a time (write e.g. 2s, 2.5s, 300ms)");
        double scale = 0;
        if (unit == "ms") scale = 1e6;
        else if (unit == "s") scale = 1e9;
        else if (unit == "min") scale = 60e9;
        else if (unit.empty())
            fail(std::string(what) + " \"" + std::string(word) + "\" has no unit (write " + std::string(word) +
                 "s or " + std::string(word) + "ms)");
        else
            fail(std::string(what) + " \"" + std::string(word) + "\" has an unknown unit \"" + std::string(unit) +
                 "\" (ms, s or min)");
        const double ns = value * scale;
        if (!std::isfinite(ns) || ns > 1e18) fail(std::string(what) + " \"" + std::string(word) + "\" is too long");
        return nanoseconds(static_cast<long long>(std::llround(ns)));
    }

    std::vector<std::size_t> buttons(std::string_view word, const std::vector<std::string>& known) const {
        std::vector<std::size_t> out;
        std::size_t from = 0;
        for (;;) {
            const std::size_t plus = word.find('+', from);
            const std::string name(word.substr(from, plus == std::string_view::npos ? std::string_view::npos
                                                                                     : plus - from));
            const auto it = std::find(known.begin(), known.end(), name);
            if (it == known.end()) {
                std::string list;
                for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
                fail(name.empty() ? "a button name is missing in \"" + std::string(word) + "\""
                                  : "unknown button \"" + name + "\" (buttons: " + list + ")");
            }
            const auto index = static_cast<std::size_t>(it - known.begin());
            if (std::find(out.begin(), out.end(), index) != out.end())
                fail("button \"" + name + "\" is named twice in \"" + std::string(word) + "\"");
            out.push_back(index);
            if (plus == std::string_view::npos) break;
            from = plus + 1;
        }
        return out;
    }

    int count(std::string_view word) const {
        int n = 0;
        const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), n);
        if (ec != std::errc() || end != word.data() + word.size() || n < 1 || n > kMaxBounces)
            fail("bounce count \"" + std::string(word) + "\" must be a whole number from 1 to " +
                 std::to_string(kMaxBounces));
        return n;
    }

    const std::string& where() const { return where_; }

private:
    std::string where_;
};

// One intended change of one button, before bounces are added.
struct Change {
    nanoseconds at{0};
    std::size_t button = 0;
    bool pressed = false;
    int line = 0;
    int bounces = 0;
    std::size_t order = 0;  // script order, to keep equal times stable
};

std::vector<std::string_view> words(std::string_view line) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        std::size_t j = i;
        while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
        if (j > i) out.push_back(line.substr(i, j - i));
        i = j;
    }
    return out;
}

}  // namespace

ButtonTimeline parseButtonTimeline(std::string_view text, const std::string& source,
                                   const std::vector<std::string>& buttons) {
    std::vector<Change> changes;
    nanoseconds previous{0};
    int lineNumber = 0;
    std::size_t pos = 0;
    while (pos <= text.size()) {
        const std::size_t eol = std::min(text.find('\n', pos), text.size());
        std::string_view line = text.substr(pos, eol - pos);
        pos = eol + 1;
        ++lineNumber;
        if (const auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
        const auto w = words(line);
        if (w.empty()) continue;
        const LineParser p(source, lineNumber);

        if (w[0] != "at" && w[0] != "after")
            p.fail("a line starts with \"at TIME\" or \"after TIME\", not \"" + std::string(w[0]) + "\"");
        if (w.size() < 4) p.fail("expected \"" + std::string(w[0]) + " TIME press|release|tap|hold BUTTON[+BUTTON]\"");
        const nanoseconds t = w[0] == "at" ? p.time(w[1], "time") : previous + p.time(w[1], "time");
        if (t < previous)
            p.fail("at " + formatTime(t) + " is before the previous line's " + formatTime(previous) +
                   " (lines must be in time order)");
        previous = t;

        const std::string_view action = w[2];
        const std::vector<std::size_t> which = p.buttons(w[3], buttons);
        std::size_t next = 4;
        nanoseconds held{0};
        if (action == "hold") {
            if (w.size() <= next) p.fail("\"hold\" needs a duration: hold " + std::string(w[3]) + " 3s");
            held = p.time(w[next++], "hold duration");
        } else if (action == "tap") {
            held = kDefaultTap;
            if (w.size() > next && w[next] != "bounce") held = p.time(w[next++], "tap duration");
        } else if (action != "press" && action != "release") {
            p.fail("unknown action \"" + std::string(action) + "\" (press, release, tap or hold)");
        }
        if ((action == "hold" || action == "tap") && held <= nanoseconds::zero())
            p.fail("the " + std::string(action) + " duration must be longer than 0");
        int bounces = 0;
        if (w.size() > next && w[next] == "bounce") {
            if (w.size() <= next + 1) p.fail("\"bounce\" needs a count: bounce 3");
            bounces = p.count(w[next + 1]);
            next += 2;
        }
        if (w.size() > next) p.fail("unexpected \"" + std::string(w[next]) + "\" at the end of the line");

        for (const std::size_t b : which) {
            if (action == "release") {
                changes.push_back({t, b, false, lineNumber, bounces, changes.size()});
            } else {
                changes.push_back({t, b, true, lineNumber, bounces, changes.size()});
                if (action != "press") changes.push_back({t + held, b, false, lineNumber, bounces, changes.size()});
            }
        }
    }

    std::stable_sort(changes.begin(), changes.end(), [](const Change& a, const Change& b) { return a.at < b.at; });

    // Check each button alternates press/release and that bounces settle before its next change.
    ButtonTimeline timeline{buttons, {}};
    std::vector<bool> down(buttons.size(), false);
    std::vector<const Change*> last(buttons.size(), nullptr);
    for (const Change& c : changes) {
        const LineParser p(source, c.line);
        const std::string& name = buttons[c.button];
        if (down[c.button] == c.pressed)
            p.fail(c.pressed ? "\"" + name + "\" is pressed at " + formatTime(c.at) + " while it is already down" +
                                   (last[c.button] ? " (pressed by line " + std::to_string(last[c.button]->line) + ")"
                                                   : std::string())
                             : "\"" + name + "\" is released at " + formatTime(c.at) + " but it is not down");
        if (const Change* before = last[c.button]) {
            const nanoseconds settle = kBounceStep * (2 * before->bounces);
            if (before->at + settle >= c.at && before->bounces > 0)
                LineParser(source, before->line)
                    .fail("the bounces of \"" + name + "\" at " + formatTime(before->at) + " last " +
                          formatTime(settle) + ", past its next change at " + formatTime(c.at));
        }
        down[c.button] = c.pressed;
        last[c.button] = &c;
        // The edge, then `bounces` pairs of contact chatter, ending on the intended level.
        for (int k = 0; k <= 2 * c.bounces; ++k)
            timeline.edges.push_back({c.at + kBounceStep * k, c.button, (k % 2 == 0) == c.pressed, c.line});
    }
    std::stable_sort(timeline.edges.begin(), timeline.edges.end(),
                     [](const TimelineEdge& a, const TimelineEdge& b) { return a.at < b.at; });
    return timeline;
}

ButtonTimeline loadButtonTimeline(const std::filesystem::path& path, const std::vector<std::string>& buttons) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw BoothError(ErrorKind::BadConfig, path.string(), "cannot read the button timeline (missing?)");
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) throw BoothError(ErrorKind::BadConfig, path.string(), "cannot read the button timeline");
    return parseButtonTimeline(text.str(), path.string(), buttons);
}

ScriptedLines::ScriptedLines(ButtonTimeline timeline, Clock& clock, SteadyTime start, std::string source)
    : timeline_(std::move(timeline)), clock_(clock), start_(start), source_(std::move(source)),
      levels_(timeline_.buttons.size(), false) {}

std::vector<bool> ScriptedLines::levels() { return levels_; }

std::vector<RawEdge> ScriptedLines::waitEdges(SteadyTime deadline) {
    std::vector<RawEdge> out;
    if (next_ >= timeline_.edges.size() || start_ + timeline_.edges[next_].at > deadline) {
        clock_.sleepUntil(deadline);
        return out;
    }
    clock_.sleepUntil(start_ + timeline_.edges[next_].at);
    const SteadyTime now = clock_.now();
    while (next_ < timeline_.edges.size() && start_ + timeline_.edges[next_].at <= now) {
        const TimelineEdge& e = timeline_.edges[next_++];
        levels_[e.button] = e.pressed;
        out.push_back({e.button, e.pressed, start_ + e.at});
    }
    return out;
}

std::string ScriptedLines::describe() const {
    return "sim timeline " + source_ + " (" + std::to_string(timeline_.edges.size()) + " edges)";
}

}  // namespace avatarbooth
