// The simulated visitor: what --visitor-does accepts, and how long it looks at its avatars before keeping.
#include "common/error.h"
#include "sim/sim_visitor.h"

#include <gtest/gtest.h>

namespace avatarbooth {
namespace {

using namespace std::chrono_literals;

TEST(SimVisitorScript, ItemsAndTheTimeSpentOnTheReveal) {
    const SimVisitorScript plain = parseSimVisitorScript("");
    EXPECT_FALSE(plain.retakeSideOnce);
    EXPECT_EQ(plain.lookAtAvatarFor, Millis(3000));

    const SimVisitorScript s = parseSimVisitorScript("retake-side,look-at-avatar=8.5s,unplug-camera");
    EXPECT_TRUE(s.retakeSideOnce);
    EXPECT_TRUE(s.unplugCameraOnce);
    EXPECT_FALSE(s.operatorFirst);
    EXPECT_EQ(s.lookAtAvatarFor, Millis(8500));
    EXPECT_EQ(parseSimVisitorScript("look-at-avatar=2").lookAtAvatarFor, Millis(2000));

    for (const char* bad : {"look-at-avatar=", "look-at-avatar=-1s", "look-at-avatar=0", "look-at-avatar=5 s",
                            "look-at-avatar=9000s", "look-at-avatar=fast", "dance"}) {
        try {
            (void)parseSimVisitorScript(bad);
            ADD_FAILURE() << bad << " was accepted";
        } catch (const BoothError& e) {
            EXPECT_EQ(e.kind(), ErrorKind::BadInput) << bad;
            EXPECT_EQ(e.where(), "--visitor-does") << bad;
            EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
        }
    }
}

TEST(SimVisitor, KeepsTheAvatarOnlyAfterLookingAtItForTheScriptedTime) {
    SimVisitorScript script;
    script.lookAtAvatarFor = 8000ms;
    SimVisitor visitor(script);
    ScreenModel reveal;
    reveal.id = ScreenId::Reveal;
    const FlowTime t0{std::chrono::seconds(100)};
    EXPECT_FALSE(visitor.step(reveal, t0).press);
    EXPECT_FALSE(visitor.step(reveal, t0 + 7999ms).press);
    const auto a = visitor.step(reveal, t0 + 8000ms);
    ASSERT_TRUE(a.press);
    EXPECT_EQ(*a.press, Button::Start);                     // keep
    EXPECT_FALSE(visitor.step(reveal, t0 + 9000ms).press);  // once
}

}  // namespace
}  // namespace avatarbooth
