// The random visitors' behaviour, screen by screen.
#include "sim/random_visitor.h"

namespace avatarbooth {

RandomVisitor::RandomVisitor(RandomVisitorOptions options) : options_(options), random_(options.seed) {}

Millis RandomVisitor::randomWait() {
    std::uniform_int_distribution<long> d(options_.minWait.count(), std::max(options_.minWait, options_.maxWait).count());
    return Millis(d(random_));
}

void RandomVisitor::newVisitor() {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double r = u(random_);
    double edge = options_.walkAwayInGuide;
    if (r < edge) {
        plan_ = u(random_) < 0.5 ? Plan::WalkAwayInFrontGuide : Plan::WalkAwayInSideGuide;
    } else if (r < (edge += options_.walkAwayAtReveal)) {
        plan_ = Plan::WalkAwayAtReveal;
    } else if (r < (edge += options_.retake)) {
        plan_ = u(random_) < 0.5 ? Plan::RetakeFront : Plan::RetakeSide;
    } else {
        plan_ = Plan::Keep;
    }
    retook_ = false;
    ++tally_.started;
}

VisitorScript::Action RandomVisitor::step(const ScreenModel& screen, FlowTime now) {
    if (screen.id != screen_ || screen.photo != photo_ || since_ == FlowTime{}) {
        screen_ = screen.id;
        photo_ = screen.photo;
        since_ = now;
        acted_ = false;
        wait_ = randomWait();
    }
    const Millis in = std::chrono::duration_cast<Millis>(now - since_);
    Action a;
    const auto pressOnce = [&](Button b) {
        if (!acted_ && in >= wait_) {
            a.press = b;
            acted_ = true;
        }
    };
    const bool leavesHere = (plan_ == Plan::WalkAwayInFrontGuide && screen.id == ScreenId::FrontGuide) ||
                            (plan_ == Plan::WalkAwayInSideGuide && screen.id == ScreenId::SideGuide);
    switch (screen.id) {
        case ScreenId::Attract:
            present_ = false;
            pressOnce(Button::Start);
            if (a.press) {
                present_ = true;
                newVisitor();
            }
            break;
        case ScreenId::FrontGuide:
        case ScreenId::SideGuide:
            if (leavesHere) {
                if (present_) ++tally_.walkedAwayInGuide;
                present_ = false;  // the guide sees nobody and gives up after its absent timeout
            } else {
                pressOnce(Button::Start);  // not waiting for the automatic countdown: it may never come
            }
            break;
        case ScreenId::Reveal:
            if (plan_ == Plan::WalkAwayAtReveal) {
                if (present_) ++tally_.walkedAwayAtReveal;
                present_ = false;
            } else if ((plan_ == Plan::RetakeFront || plan_ == Plan::RetakeSide) && !retook_) {
                pressOnce(Button::Retake);
            } else {
                pressOnce(Button::Start);
                if (a.press) ++tally_.keepPresses;
            }
            break;
        case ScreenId::RetakeChoice:
            if (!retook_) {
                pressOnce(plan_ == Plan::RetakeFront ? Button::Start : Button::Retake);
                if (a.press) {
                    retook_ = true;
                    ++(plan_ == Plan::RetakeFront ? tally_.retakesFront : tally_.retakesSide);
                }
            }
            break;
        case ScreenId::Thanks:
            present_ = false;
            break;
        default:
            break;
    }
    if (!present_) a.scene = SimScene::Empty;
    else if (screen.id == ScreenId::Reveal || screen.id == ScreenId::RetakeChoice) a.scene = SimScene::Front;
    else if (screen.id == ScreenId::SideGuide || screen.photo == Photo::Side || screen.id == ScreenId::Processing)
        a.scene = SimScene::Side;
    else a.scene = SimScene::Front;
    return a;
}

}  // namespace avatarbooth
