// Limited animation from motion data (Kitamura 2015, ch. 5; METHODS §3.1): omitted in-betweens (Algorithm 2) and
// holds (Algorithm 3) chosen by the speed of every frame, the sum of squared joint displacements (SSD).
//
// The filter never changes a pose: it decides which input frame each displayed frame shows. A result is a
// "timing": timing[k] = the index of the input frame shown at display frame k (the identity is full animation).
//
// How the thesis' pseudo-code is read (decisions where it is not explicit):
// - Frames are numbered from 0 here (the thesis counts from 1). SSD(k) = sum_i |p_i(k) - p_i(k-1)|^2 is defined
//   for k >= 1 on the CURRENT sequence: it is recomputed after every deletion, insertion and overwrite.
// - argmax / argmin ties go to the earliest frame (the lowest k).
// - Algorithm 2, one iteration: delete the frame k_max = argmax SSD(k); then, on the shortened sequence, insert a
//   copy of frame k_min - 1 right after it, k_min = argmin SSD(k) among the frames whose predecessor may still be
//   copied. A copy has SSD 0, so the next iterations pile copies into the same slow gap until it is full, then
//   move to the next slowest gap ("すでに 3 フレームコピーされたフレーム間にはコピーせず").
// - Algorithm 3, one iteration: k_min = argmin SSD(k) among the frames whose predecessor may still be copied and
//   whose own picture is shown by no other frame; overwrite frame k_min with frame k_min - 1. (Without the second
//   condition an overwritten frame, now at SSD 0, would be picked again as a no-op, or a hold would only be
//   shifted by one frame; with it every iteration removes one picture and adds one held frame, which is how the
//   thesis' table counts N_hf: "frames copied by holds".)
// - "At most 3 copies" (#DUPLICATED < 3, #COPIED < 3): counted per picture, over both algorithms, as the number of
//   displayed frames showing the same input frame minus one. Copies are always made next to their original, so
//   the frames showing one picture are consecutive and no picture stands still for more than 1 + maxCopies
//   frames. (Counting per slot index, literally, would let a hold chain s, s, s, ... grow without end: each slot
//   copied forward once.)
// - An iteration that finds no eligible frame stops that algorithm early (only possible for very short motions);
//   the result says how many iterations were done.
#pragma once

#include <glm/glm.hpp>

#include <cstddef>
#include <vector>

namespace avatarbooth {

// One input frame: the positions of the n joints (any unit; the thesis uses world space).
using JointPositions = std::vector<glm::dvec3>;

// sum_i |a_i - b_i|^2 (eq. 5.1). Throws std::invalid_argument when the joint counts differ.
double squaredDisplacement(const JointPositions& a, const JointPositions& b);

// SSD(k) of a timing over a motion, k = 0 .. size-1; SSD(0) is 0 (no predecessor).
std::vector<double> frameSpeeds(const std::vector<JointPositions>& motion, const std::vector<int>& timing);

// The identity timing 0, 1, ..., frames-1 (full animation).
std::vector<int> fullTiming(std::size_t frames);

// How many displayed frames around `k` show the same input frame as k, minus one.
int copiesOfPicture(const std::vector<int>& timing, std::size_t k);

struct FilterResult {
    std::vector<int> timing;
    int iterations = 0;  // how many of the requested iterations were done
};

// Algorithm 2 (naka-nashi), `iterations` = N_io times, on an existing timing (the identity for raw motion).
// Keeps the length. Throws std::invalid_argument for a timing index outside the motion or negative counts.
FilterResult omitInbetweens(const std::vector<JointPositions>& motion, std::vector<int> timing, int iterations,
                            int maxCopies = 3);

// Algorithm 3 (koma-dori), `iterations` = N_hf times. Keeps the length.
FilterResult holdFrames(const std::vector<JointPositions>& motion, std::vector<int> timing, int iterations,
                        int maxCopies = 3);

// The alternative the thesis tried and rejected (§5.2.4): SSD computed once, the `count` fastest frames deleted
// at once, and copies inserted at the `count` slowest remaining gaps of that same SSD (one per gap, the same copy
// limit; the length is kept when there are that many such gaps). Kept to show the difference: its deletions
// scatter where Algorithm 2's run together. `iterations` in the result = frames deleted.
FilterResult omitInbetweensAllAtOnce(const std::vector<JointPositions>& motion, int count, int maxCopies = 3);

struct LimitedAnimationSettings {
    int inbetweenOmissions = 4;  // N_io: frames omitted where the motion is fastest (the thesis found 4-6 right)
    int holdFrames = 0;          // N_hf: frames overwritten by their predecessor (the thesis: about a third)
    int maxCopies = 3;           // the most copies of one picture ("at most 3 copies")
};

// Naka-nashi first, then holds (the thesis' order), from the identity timing.
std::vector<int> limitAnimation(const std::vector<JointPositions>& motion, const LimitedAnimationSettings& settings);

}  // namespace avatarbooth
