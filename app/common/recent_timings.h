// Timing figures of a run that may last weeks, in memory that does not grow with it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace avatarbooth {

// Durations (any unit) as they come: the median over the most recent `keep` of them, and the slowest and the
// count over the whole run. The kiosk records every reveal frame; a list of all of them grew by about 2.4 kB per
// visitor and showed as a slow climb in the soak (tests/reliability/soak.cpp), so only the recent ones are held.
class RecentTimings {
public:
    explicit RecentTimings(std::size_t keep = 2000);

    void add(double duration);
    // The median of the recent durations (the upper one of the two middle ones for an even count); 0 when none.
    double median() const;
    // The slowest duration of the whole run; 0 when none.
    double slowest() const { return slowest_; }
    // How many were added over the whole run.
    std::uint64_t count() const { return count_; }
    bool empty() const { return count_ == 0; }

private:
    std::size_t keep_;
    std::vector<double> recent_;  // a ring once full: `next_` is the oldest
    std::size_t next_ = 0;
    std::uint64_t count_ = 0;
    double slowest_ = 0.0;
};

}  // namespace avatarbooth
