// The simulated visitor's behaviour, screen by screen.
#include "sim/sim_visitor.h"

namespace avatarbooth {

VisitorScript::Action SimVisitor::step(const ScreenModel& screen, FlowTime now) {
    if (screen.id != screen_ || screen.photo != photo_ || since_ == FlowTime{}) {
        screen_ = screen.id;
        photo_ = screen.photo;
        since_ = now;
        acted_ = false;
    }
    const Millis in = std::chrono::duration_cast<Millis>(now - since_);
    Action a;
    const auto pressOnce = [&](Button b, Millis after) {
        if (!acted_ && in >= after) {
            a.press = b;
            acted_ = true;
        }
    };
    switch (screen.id) {
        case ScreenId::Attract:
            present_ = false;
            pressOnce(Button::Start, script_.walkUpAfter);
            if (a.press) present_ = true;
            break;
        case ScreenId::FrontGuide:
        case ScreenId::SideGuide:
            // The guide counts down by itself once it sees a good pose; a visitor left waiting presses Start.
            pressOnce(Button::Start, script_.pressIfStuckAfter);
            break;
        case ScreenId::Reveal:
            if (script_.retakeSideOnce && !retook_) {
                pressOnce(Button::Retake, script_.lookAtAvatarFor);
                if (a.press) retook_ = true;
            } else {
                pressOnce(Button::Start, script_.lookAtAvatarFor);
            }
            break;
        case ScreenId::RetakeChoice:
            // Retake (the side photo's button) picks the side photo.
            pressOnce(Button::Retake, Millis(800));
            break;
        case ScreenId::Thanks:
            present_ = false;  // walks away with the code
            break;
        default:
            break;
    }
    if (!present_) a.scene = SimScene::Empty;
    else if (screen.id == ScreenId::SideGuide || screen.photo == Photo::Side || screen.id == ScreenId::Processing)
        a.scene = SimScene::Side;
    else a.scene = SimScene::Front;
    // During the reveal and the retake question the visitor faces the screen again.
    if (present_ && (screen.id == ScreenId::Reveal || screen.id == ScreenId::RetakeChoice)) a.scene = SimScene::Front;
    return a;
}

}  // namespace avatarbooth
