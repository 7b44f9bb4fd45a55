// A random (seeded) stream of simulated visitors for the soak and fault tests: each one walks up after a random
// wait, presses with random timing, sometimes walks away from a guide or from the reveal, sometimes retakes the
// front or the side photo, and keeps or leaves the avatar. Plain logic like SimVisitor.
#pragma once

#include "kiosk/kiosk.h"

#include <cstdint>
#include <random>

namespace avatarbooth {

struct RandomVisitorOptions {
    std::uint64_t seed = 1;
    // Shares of the visitors (the rest keep their avatar, after a retake or not).
    double walkAwayInGuide = 0.15;   // leave during the front or side guide (the guide's absent timeout)
    double walkAwayAtReveal = 0.15;  // leave the reveal without deciding (the reveal timeout discards it)
    double retake = 0.3;             // ask for a retake at the reveal (front or side, half each)
    // Waits before each press, drawn uniformly from [min, max].
    Millis minWait{200};
    Millis maxWait{900};
};

// What the visitors did, as planned (the kiosk's report says what the booth made of it).
struct RandomVisitorTally {
    int started = 0;
    int walkedAwayInGuide = 0;
    int walkedAwayAtReveal = 0;
    int retakesFront = 0;
    int retakesSide = 0;
    int keepPresses = 0;
};

class RandomVisitor final : public VisitorScript {
public:
    explicit RandomVisitor(RandomVisitorOptions options = {});
    Action step(const ScreenModel& screen, FlowTime now) override;
    const RandomVisitorTally& tally() const { return tally_; }

private:
    enum class Plan { Keep, WalkAwayInFrontGuide, WalkAwayInSideGuide, WalkAwayAtReveal, RetakeFront, RetakeSide };
    void newVisitor();
    Millis randomWait();

    RandomVisitorOptions options_;
    std::mt19937_64 random_;
    RandomVisitorTally tally_;
    Plan plan_ = Plan::Keep;
    Millis wait_{0};            // before this screen's press
    ScreenId screen_ = ScreenId::Attract;
    Photo photo_ = Photo::Front;
    FlowTime since_{};
    bool acted_ = false;        // pressed on this screen already
    bool present_ = false;      // standing at the booth
    bool retook_ = false;       // this visitor's retake is done
};

}  // namespace avatarbooth
