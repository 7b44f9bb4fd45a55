// Limited animation: Kitamura's Algorithms 2 (omitted in-betweens) and 3 (holds), and the rejected all-at-once
// variant for comparison. See limited_animation.h for how the pseudo-code is read.
#include "reveal/animation/limited_animation.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace avatarbooth {

double squaredDisplacement(const JointPositions& a, const JointPositions& b) {
    if (a.size() != b.size())
        throw std::invalid_argument("limited animation: frames with " + std::to_string(a.size()) + " and " +
                                    std::to_string(b.size()) + " joints");
    double sum = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const glm::dvec3 d = a[i] - b[i];
        sum += glm::dot(d, d);
    }
    return sum;
}

namespace {

void checkTiming(const std::vector<JointPositions>& motion, const std::vector<int>& timing) {
    for (const int f : timing)
        if (f < 0 || static_cast<std::size_t>(f) >= motion.size())
            throw std::invalid_argument("limited animation: the timing shows frame " + std::to_string(f) +
                                        " of a motion of " + std::to_string(motion.size()) + " frames");
}

void checkCounts(int iterations, int maxCopies) {
    if (iterations < 0) throw std::invalid_argument("limited animation: a negative number of iterations");
    if (maxCopies < 0) throw std::invalid_argument("limited animation: a negative copy limit");
}

// The first k in [1, size) with the largest speed; 0 when there is none.
std::size_t fastestFrame(const std::vector<double>& speeds) {
    std::size_t best = 0;
    for (std::size_t k = 1; k < speeds.size(); ++k)
        if (best == 0 || speeds[k] > speeds[best]) best = k;
    return best;
}

}  // namespace

std::vector<double> frameSpeeds(const std::vector<JointPositions>& motion, const std::vector<int>& timing) {
    checkTiming(motion, timing);
    std::vector<double> speeds(timing.size(), 0.0);
    for (std::size_t k = 1; k < timing.size(); ++k)
        speeds[k] = squaredDisplacement(motion[static_cast<std::size_t>(timing[k])],
                                        motion[static_cast<std::size_t>(timing[k - 1])]);
    return speeds;
}

std::vector<int> fullTiming(std::size_t frames) {
    std::vector<int> timing(frames);
    std::iota(timing.begin(), timing.end(), 0);
    return timing;
}

int copiesOfPicture(const std::vector<int>& timing, std::size_t k) {
    if (k >= timing.size()) throw std::out_of_range("copiesOfPicture: frame " + std::to_string(k) + " of " +
                                                    std::to_string(timing.size()));
    std::size_t lo = k, hi = k;
    while (lo > 0 && timing[lo - 1] == timing[k]) --lo;
    while (hi + 1 < timing.size() && timing[hi + 1] == timing[k]) ++hi;
    return static_cast<int>(hi - lo);
}

FilterResult omitInbetweens(const std::vector<JointPositions>& motion, std::vector<int> timing, int iterations,
                            int maxCopies) {
    checkTiming(motion, timing);
    checkCounts(iterations, maxCopies);
    FilterResult result;
    for (int i = 0; i < iterations && timing.size() >= 3; ++i) {
        const std::size_t kMax = fastestFrame(frameSpeeds(motion, timing));
        std::vector<int> shortened = timing;
        shortened.erase(shortened.begin() + static_cast<std::ptrdiff_t>(kMax));
        // SSD recomputed on the shortened sequence: the gap left by the deletion is now the two frames' distance.
        const std::vector<double> speeds = frameSpeeds(motion, shortened);
        std::size_t kMin = 0;
        for (std::size_t k = 1; k < shortened.size(); ++k)
            if (copiesOfPicture(shortened, k - 1) < maxCopies && (kMin == 0 || speeds[k] < speeds[kMin])) kMin = k;
        if (kMin == 0) break;  // every gap is full: stop rather than shorten the motion
        shortened.insert(shortened.begin() + static_cast<std::ptrdiff_t>(kMin), shortened[kMin - 1]);
        timing = std::move(shortened);
        ++result.iterations;
    }
    result.timing = std::move(timing);
    return result;
}

FilterResult holdFrames(const std::vector<JointPositions>& motion, std::vector<int> timing, int iterations,
                        int maxCopies) {
    checkTiming(motion, timing);
    checkCounts(iterations, maxCopies);
    FilterResult result;
    for (int i = 0; i < iterations; ++i) {
        const std::vector<double> speeds = frameSpeeds(motion, timing);
        std::size_t kMin = 0;
        for (std::size_t k = 1; k < timing.size(); ++k)
            if (copiesOfPicture(timing, k) == 0 && copiesOfPicture(timing, k - 1) < maxCopies &&
                (kMin == 0 || speeds[k] < speeds[kMin]))
                kMin = k;
        if (kMin == 0) break;
        timing[kMin] = timing[kMin - 1];
        ++result.iterations;
    }
    result.timing = std::move(timing);
    return result;
}

FilterResult omitInbetweensAllAtOnce(const std::vector<JointPositions>& motion, int count, int maxCopies) {
    checkCounts(count, maxCopies);
    const std::vector<int> identity = fullTiming(motion.size());
    const std::vector<double> speeds = frameSpeeds(motion, identity);
    std::vector<std::size_t> byDescendingSpeed;
    for (std::size_t k = 1; k < speeds.size(); ++k) byDescendingSpeed.push_back(k);
    std::stable_sort(byDescendingSpeed.begin(), byDescendingSpeed.end(),
                     [&](std::size_t a, std::size_t b) { return speeds[a] > speeds[b]; });
    const std::size_t deletions = std::min(static_cast<std::size_t>(count), byDescendingSpeed.size());
    std::vector<bool> deleted(motion.size(), false);
    for (std::size_t i = 0; i < deletions; ++i) deleted[byDescendingSpeed[i]] = true;

    // Gaps that survive the deletions (both frames kept), slowest first (ties: earliest), one copy each: each
    // copies a different picture, so the copy limit only matters when it is 0.
    std::vector<std::size_t> byAscendingSpeed(byDescendingSpeed.begin(), byDescendingSpeed.end());
    std::stable_sort(byAscendingSpeed.begin(), byAscendingSpeed.end(),
                     [&](std::size_t a, std::size_t b) { return speeds[a] < speeds[b]; });
    std::vector<bool> copyBefore(motion.size(), false);
    std::size_t copies = 0;
    for (const std::size_t k : byAscendingSpeed) {
        if (copies >= deletions || maxCopies < 1) break;
        if (deleted[k] || deleted[k - 1]) continue;
        copyBefore[k] = true;
        ++copies;
    }
    FilterResult result;
    for (std::size_t k = 0; k < motion.size(); ++k) {
        if (copyBefore[k]) result.timing.push_back(static_cast<int>(k - 1));
        if (!deleted[k]) result.timing.push_back(static_cast<int>(k));
    }
    result.iterations = static_cast<int>(deletions);
    return result;
}

std::vector<int> limitAnimation(const std::vector<JointPositions>& motion, const LimitedAnimationSettings& settings) {
    FilterResult omitted = omitInbetweens(motion, fullTiming(motion.size()), settings.inbetweenOmissions,
                                          settings.maxCopies);
    return holdFrames(motion, std::move(omitted.timing), settings.holdFrames, settings.maxCopies).timing;
}

}  // namespace avatarbooth
