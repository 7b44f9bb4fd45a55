// A std::ostream that hands each line libcamera writes to spdlog, installed with libcamera::logSetStream.
#include "drivers/camera/libcamera_log.h"

#include <ostream>  // before libcamera/logging.h, which uses std::ostream without including it (0.0.3)

#include <libcamera/logging.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdlib>
#include <mutex>
#include <streambuf>

namespace avatarbooth {
namespace {

constexpr std::string_view kSpace = " \t";

// Collects characters until a newline and forwards the line. libcamera writes each message with one write() from
// whichever of its threads logs, so the buffer is guarded.
class SpdlogLineBuffer : public std::streambuf {
public:
    // libcamera 0.0.3's logSetLevel only reaches categories that have already logged once (they register on first
    // use), so the level is applied here, to every line, instead.
    explicit SpdlogLineBuffer(bool keepLowerLevels) : keepLowerLevels_(keepLowerLevels) {}

protected:
    int_type overflow(int_type ch) override {
        if (traits_type::eq_int_type(ch, traits_type::eof())) return traits_type::not_eof(ch);
        const char c = traits_type::to_char_type(ch);
        xsputn(&c, 1);
        return ch;
    }

    std::streamsize xsputn(const char* s, std::streamsize n) override {
        std::lock_guard lock(mutex_);
        for (std::streamsize i = 0; i < n; ++i) {
            if (s[i] != '\n') {
                line_ += s[i];
                continue;
            }
            forward(line_);
            line_.clear();
        }
        return n;
    }

private:
    void forward(const std::string& line) const {
        const LibcameraLogLine parsed = parseLibcameraLogLine(line);
        if (parsed.level < spdlog::level::warn && !keepLowerLevels_) return;
        spdlog::log(parsed.level, "libcamera: {}", parsed.text);
    }

    const bool keepLowerLevels_;
    std::mutex mutex_;
    std::string line_;
};

}  // namespace

LibcameraLogLine parseLibcameraLogLine(std::string_view line) {
    std::string_view rest = line;
    // "[time] [thread] " before the severity.
    for (int bracket = 0; bracket < 2; ++bracket) {
        const auto start = rest.find_first_not_of(kSpace);
        const auto close = rest.find(']');
        if (start == std::string_view::npos || rest[start] != '[' || close == std::string_view::npos)
            return {spdlog::level::warn, std::string(line)};
        rest.remove_prefix(close + 1);
    }
    const auto wordStart = rest.find_first_not_of(kSpace);
    if (wordStart == std::string_view::npos) return {spdlog::level::warn, std::string(line)};
    rest.remove_prefix(wordStart);
    const auto wordEnd = std::min(rest.find_first_of(kSpace), rest.size());
    const std::string_view severity = rest.substr(0, wordEnd);
    rest.remove_prefix(wordEnd);
    const auto textStart = rest.find_first_not_of(kSpace);
    const std::string text(textStart == std::string_view::npos ? std::string_view() : rest.substr(textStart));
    if (severity == "DEBUG") return {spdlog::level::debug, text};
    if (severity == "INFO") return {spdlog::level::info, text};
    if (severity == "WARN") return {spdlog::level::warn, text};
    if (severity == "ERROR") return {spdlog::level::err, text};
    if (severity == "FATAL") return {spdlog::level::critical, text};
    return {spdlog::level::warn, std::string(line)};
}

void routeLibcameraLogToSpdlog() {
    static std::once_flag once;
    std::call_once(once, [] {
        // An operator who sent libcamera's log to a file (or syslog) for debugging keeps it there.
        if (const char* file = std::getenv("LIBCAMERA_LOG_FILE"); file != nullptr && *file != '\0') return;
        const char* asked = std::getenv("LIBCAMERA_LOG_LEVELS");
        // Leaked on purpose: libcamera's logger is a static destroyed at exit in an order we do not control, and
        // must never find its stream gone.
        auto* buffer = new SpdlogLineBuffer(asked != nullptr && *asked != '\0');
        auto* stream = new std::ostream(buffer);
        libcamera::logSetStream(stream, false);
    });
}

}  // namespace avatarbooth
