// Scripted button timelines: what each line expands to, and errors that name the file, line and problem.
#include "drivers/gpio/button_timeline.h"

#include "common/error.h"

#include <gtest/gtest.h>

namespace avatarbooth {
namespace {

using namespace std::chrono_literals;
using E = TimelineEdge;
const std::vector<std::string> kTimelineButtons{"start", "retake"};
constexpr std::size_t S = 0, R = 1;

TEST(GpioTimeline, EveryKindOfLineExpandsToExactEdges) {
    const std::string script =
        "# a visitor's session\n"
        "at 2.0s press start\n"
        "at 2.1s release start   # released again\n"
        "\n"
        "   after 900ms tap retake\n"
        "at 5s hold start+retake 3s\n"
        "at 10s tap start 50ms bounce 2\n"
        "at 0.2min press retake\n";
    const ButtonTimeline t = parseButtonTimeline(script, "visit.timeline", kTimelineButtons);
    EXPECT_EQ(t.buttons, kTimelineButtons);
    const std::vector<E> expected{
        {2000ms, S, true, 2},    {2100ms, S, false, 3},   {3000ms, R, true, 5},    {3100ms, R, false, 5},
        {5000ms, S, true, 6},    {5000ms, R, true, 6},    {8000ms, S, false, 6},   {8000ms, R, false, 6},
        {10000ms, S, true, 7},   {10001ms, S, false, 7},  {10002ms, S, true, 7},   {10003ms, S, false, 7},
        {10004ms, S, true, 7},   {10050ms, S, false, 7},  {10051ms, S, true, 7},   {10052ms, S, false, 7},
        {10053ms, S, true, 7},   {10054ms, S, false, 7},  {12000ms, R, true, 8},
    };
    EXPECT_EQ(t.edges, expected);
}

TEST(GpioTimeline, EmptyAndCommentOnlyScriptsHaveNoEdges) {
    EXPECT_TRUE(parseButtonTimeline("", "x", kTimelineButtons).edges.empty());
    EXPECT_TRUE(parseButtonTimeline("# nothing\n\n   \n", "x", kTimelineButtons).edges.empty());
}

// The error for `script`, which must be BadConfig.
std::string timelineErrorOf(const std::string& script) {
    try {
        parseButtonTimeline(script, "s.timeline", kTimelineButtons);
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        return e.what();
    }
    ADD_FAILURE() << "no error for: " << script;
    return {};
}

TEST(GpioTimeline, ErrorsNameFileLineAndProblem) {
    EXPECT_EQ(timelineErrorOf("at 1s press start\nat 2 release start"),
              "s.timeline:2: time \"2\" has no unit (write 2s or 2ms)");
    EXPECT_EQ(timelineErrorOf("at 2h press start"), "s.timeline:1: time \"2h\" has an unknown unit \"h\" (ms, s or min)");
    EXPECT_EQ(timelineErrorOf("at soon press start"),
              "s.timeline:1: time \"soon\" is not a time (write e.g. 2s, 2.5s, 300ms)");
    EXPECT_EQ(timelineErrorOf("\n\nat 2s push start"), "s.timeline:3: unknown action \"push\" (press, release, tap or hold)");
    EXPECT_EQ(timelineErrorOf("at 2s press strat"), "s.timeline:1: unknown button \"strat\" (buttons: start, retake)");
    EXPECT_EQ(timelineErrorOf("at 2s press start+"), "s.timeline:1: a button name is missing in \"start+\"");
    EXPECT_EQ(timelineErrorOf("at 2s hold start+start 1s"), "s.timeline:1: button \"start\" is named twice in \"start+start\"");
    EXPECT_EQ(timelineErrorOf("at 3s press start\nat 2s release start"),
              "s.timeline:2: at 2s is before the previous line's 3s (lines must be in time order)");
    EXPECT_EQ(timelineErrorOf("at 1s press start\nat 2s press start"),
              "s.timeline:2: \"start\" is pressed at 2s while it is already down (pressed by line 1)");
    EXPECT_EQ(timelineErrorOf("at 1s release retake"), "s.timeline:1: \"retake\" is released at 1s but it is not down");
    EXPECT_EQ(timelineErrorOf("at 1s hold start 5s\nat 3s release start"),
              "s.timeline:1: \"start\" is released at 6s but it is not down");
    EXPECT_EQ(timelineErrorOf("at 1s hold start"), "s.timeline:1: \"hold\" needs a duration: hold start 3s");
    EXPECT_EQ(timelineErrorOf("at 1s hold start 0s"), "s.timeline:1: the hold duration must be longer than 0");
    EXPECT_EQ(timelineErrorOf("at 1s tap start bounce"), "s.timeline:1: \"bounce\" needs a count: bounce 3");
    EXPECT_EQ(timelineErrorOf("at 1s tap start bounce 0"),
              "s.timeline:1: bounce count \"0\" must be a whole number from 1 to 50");
    EXPECT_EQ(timelineErrorOf("at 1s tap start 2ms bounce 3"),
              "s.timeline:1: the bounces of \"start\" at 1s last 0.006s, past its next change at 1.002s");
    EXPECT_EQ(timelineErrorOf("at 1s press start now"), "s.timeline:1: unexpected \"now\" at the end of the line");
    EXPECT_EQ(timelineErrorOf("in 1s press start"),
              "s.timeline:1: a line starts with \"at TIME\" or \"after TIME\", not \"in\"");
    EXPECT_EQ(timelineErrorOf("at 1s press"), "s.timeline:1: expected \"at TIME press|release|tap|hold BUTTON[+BUTTON]\"");
}

}  // namespace
}  // namespace avatarbooth
