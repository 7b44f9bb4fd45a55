// The simulated visitor's behaviour, screen by screen.
#include "sim/sim_visitor.h"

#include "common/error.h"

#include <sstream>

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
    if (screen.id == ScreenId::OperatorMenu && screen.menuPage != page_) {
        page_ = screen.menuPage;  // a new page: look at it before pressing again
        since_ = now;
        acted_ = false;
    }
    const Millis inPage = std::chrono::duration_cast<Millis>(now - since_);
    if (script_.operatorFirst && operatorStep_ < 6) {
        // The operator: lock combination held from the attract screen, then through the menu to "free disk"
        // (Retake moves, Start chooses), back (any press), down to "exit" and out.
        // (Back on the attract screen without the menu, e.g. the guide timed out: hold the combination again.)
        if (operatorStep_ <= 1 && screen.id == ScreenId::Attract && in >= Millis(800) && !acted_) {
            acted_ = true;
            a.press = Button::Start;
            a.pressWith = Button::Retake;
            a.holdFor = script_.lockHold;
            operatorStep_ = 1;
        } else if (screen.id == ScreenId::OperatorMenu && inPage >= Millis(1500) && !acted_) {
            const bool onMenu = screen.menuPage == OperatorPage::Menu;
            if (operatorStep_ == 1 && onMenu && screen.menuItem != OperatorItem::FreeDisk) a.press = Button::Retake;
            else if (operatorStep_ == 1 && onMenu) a.press = Button::Start, operatorStep_ = 2;
            else if (operatorStep_ == 2 && !onMenu) a.press = Button::Start, operatorStep_ = 3;
            else if (operatorStep_ == 3 && onMenu && screen.menuItem != OperatorItem::ExitMenu) a.press = Button::Retake;
            else if (operatorStep_ == 3 && onMenu) a.press = Button::Start, operatorStep_ = 6;
            if (a.press) acted_ = true;
        }
        // (Meanwhile the Start of the combination has begun a session: the menu opens once the hold is long enough.)
        if (screen.id == ScreenId::OperatorMenu && screen.menuItem != lastItem_) {
            lastItem_ = screen.menuItem;
            since_ = now;  // moved: look before pressing again
            acted_ = false;
        }
        a.scene = SimScene::Empty;
        return a;
    }
    switch (screen.id) {
        case ScreenId::Attract:
            present_ = false;
            pressOnce(Button::Start, script_.walkUpAfter);
            if (a.press) present_ = true;
            break;
        case ScreenId::FrontGuide:
        case ScreenId::SideGuide:
            // The guide counts down by itself once it sees a good pose; a visitor left waiting presses Start.
            if (script_.unplugCameraOnce && !unplugged_ && screen.id == ScreenId::FrontGuide &&
                in >= script_.unplugAfter) {
                a.cameraPlugged = false;
                unplugged_ = true;
                break;
            }
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
        case ScreenId::CameraLost:
            if (unplugged_ && !pluggedBack_ && in >= script_.plugBackAfter) {
                a.cameraPlugged = true;
                pluggedBack_ = true;
            }
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

namespace {

// "8s" or "8" (seconds, > 0, at most an hour) for an item of --visitor-does.
Millis parseSeconds(const std::string& item, std::string value) {
    if (!value.empty() && value.back() == 's') value.pop_back();
    double seconds = 0.0;
    std::size_t used = 0;
    try {
        seconds = std::stod(value, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != value.size() || !(seconds > 0.0) || seconds > 3600.0)
        throw BoothError(ErrorKind::BadInput, "--visitor-does",
                         "\"" + item + "\": the time must be seconds between 0 and 3600, e.g. look-at-avatar=8s");
    return Millis(static_cast<long long>(seconds * 1000.0));
}

}  // namespace

SimVisitorScript parseSimVisitorScript(const std::string& list) {
    SimVisitorScript script;
    std::stringstream in(list);
    std::string item;
    while (std::getline(in, item, ',')) {
        if (item == "retake-side") script.retakeSideOnce = true;
        else if (item == "unplug-camera") script.unplugCameraOnce = true;
        else if (item == "operator-menu") script.operatorFirst = true;
        else if (item.rfind("look-at-avatar=", 0) == 0) script.lookAtAvatarFor = parseSeconds(item, item.substr(15));
        else if (!item.empty())
            throw BoothError(ErrorKind::BadInput, "--visitor-does",
                             "unknown item \"" + item +
                                 "\" (retake-side, unplug-camera, operator-menu, look-at-avatar=SECONDSs)");
    }
    return script;
}

}  // namespace avatarbooth
