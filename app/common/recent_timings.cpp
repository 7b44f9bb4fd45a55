#include "common/recent_timings.h"

#include <algorithm>

namespace avatarbooth {

RecentTimings::RecentTimings(std::size_t keep) : keep_(std::max<std::size_t>(1, keep)) { recent_.reserve(keep_); }

void RecentTimings::add(double duration) {
    if (recent_.size() < keep_) {
        recent_.push_back(duration);
    } else {
        recent_[next_] = duration;
        next_ = (next_ + 1) % keep_;
    }
    slowest_ = count_ == 0 ? duration : std::max(slowest_, duration);
    ++count_;
}

double RecentTimings::median() const {
    if (recent_.empty()) return 0.0;
    std::vector<double> v = recent_;
    const auto middle = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), middle, v.end());
    return *middle;
}

}  // namespace avatarbooth
