// Limited animation at the sizes of Kitamura's table 5.1 (Pitch 129 frames N_io 4 N_hf 33, Kick 92/4/30, Tennis
// 88/4/29, Baseball swing 120/6/40; the thesis reports 27-69 ms) with our rig's 5 points and a 20-joint body, the
// avatar's reveal played limited, and the character maker's costs (proportions, mapping, character head).
// Prints figures (medians of 5 repetitions); never fails on speed.
#include "reveal/animation/avatar_motion.h"
#include "reveal/animation/limited_animation.h"
#include "reveal/character/character_head.h"
#include "reveal/character/proportions.h"

#include <benchmark/benchmark.h>

#include <cmath>

using namespace avatarbooth;

namespace {

// A mocap-like single action: every joint swings on its own slow sine, and the "arm" joints (the second half)
// make one fast swing a third of the way through (a throw).
std::vector<JointPositions> actionMotion(int frames, int joints) {
    std::vector<JointPositions> motion;
    for (int k = 0; k < frames; ++k) {
        const double t = static_cast<double>(k) / frames;
        JointPositions p;
        for (int i = 0; i < joints; ++i) {
            const double phase = 0.7 * i;
            glm::dvec3 q(100.0 * std::sin(2.0 * t + phase), 80.0 * std::cos(1.5 * t + phase) + 10.0 * i, 20.0 * i);
            if (i >= joints / 2) q.x += 400.0 * (1.0 / (1.0 + std::exp(-(t - 0.35) * 60.0)));  // the swing
            p.push_back(q);
        }
        motion.push_back(p);
    }
    return motion;
}

void BM_LimitedAnimation(benchmark::State& state) {
    const int frames = static_cast<int>(state.range(0)), nIo = static_cast<int>(state.range(1)),
              nHf = static_cast<int>(state.range(2)), joints = static_cast<int>(state.range(3));
    const auto motion = actionMotion(frames, joints);
    LimitedAnimationSettings settings;
    settings.inbetweenOmissions = nIo;
    settings.holdFrames = nHf;
    for (auto _ : state) benchmark::DoNotOptimize(limitAnimation(motion, settings));
    state.counters["frames"] = frames;
    state.counters["joints"] = joints;
}
// frames, N_io, N_hf, joints: the thesis' four motions, with 5 points (our rig) and 20 joints (a body).
BENCHMARK(BM_LimitedAnimation)
    ->ArgsProduct({{129}, {4}, {33}, {5, 20}})
    ->ArgsProduct({{92}, {4}, {30}, {5, 20}})
    ->ArgsProduct({{88}, {4}, {29}, {5, 20}})
    ->ArgsProduct({{120}, {6}, {40}, {5, 20}})
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

// The whole reveal as the kiosk would ask for it: sample 123 frames, kinematics, filter, joint rotations.
void BM_RevealPlayback(benchmark::State& state) {
    AnimationSettings settings;
    settings.style = state.range(0) == 0 ? AnimationStyle::Limited : AnimationStyle::Full;
    const MotionClip clip = revealMotion();
    for (auto _ : state) benchmark::DoNotOptimize(playAnimation(clip, settings));
    state.SetLabel(animationStyleName(settings.style));
}
BENCHMARK(BM_RevealPlayback)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);

// Narita's ratios from 21 points.
void BM_NaritaProportions(benchmark::State& state) {
    const BaseHead& base = builtinBaseHead();
    const NaritaPoints points = measureHead(base.mesh, base, base.earHoleCentre).mapping.points;
    for (auto _ : state) benchmark::DoNotOptimize(computeProportions(points));
}
BENCHMARK(BM_NaritaProportions)->Unit(benchmark::kMicrosecond)->Repetitions(5)->ReportAggregatesOnly(true);

// The 21 points from landmarks and a silhouette (the base head seen as a 808x1268 photo: edges, ear notches).
void BM_NaritaMapping(benchmark::State& state) {
    const BaseHead& base = builtinBaseHead();
    const MeshFrontView view = frontViewOf(base.mesh, base, base.earHoleCentre, 4.0);
    for (auto _ : state) benchmark::DoNotOptimize(mapNaritaPoints(view.input));
}
BENCHMARK(BM_NaritaMapping)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);

// The character head as a fit makes it on the MakeHuman head: the Jacobian of its modifiers, 4 measure-and-solve
// rounds and a 512-texel toon texture (and 1024).
void BM_CharacterHead(benchmark::State& state) {
    if (findMakeHumanBaseHead().empty()) {
        state.SkipWithError("the MakeHuman base head was not built");
        return;
    }
    const BaseHead& base = *productBaseHead();
    CharacterProportions target = measureHead(base.mesh, base, base.earHoleCentre).proportions;
    target.r[2] *= 1.2;
    target.r[0] *= 1.1;
    CharacterSettings settings;
    settings.textureSize = static_cast<int>(state.range(0));
    for (auto _ : state) benchmark::DoNotOptimize(makeCharacterHead(base, target, settings));
}
BENCHMARK(BM_CharacterHead)->Arg(512)->Arg(1024)->Unit(benchmark::kMillisecond)->Repetitions(3)->ReportAggregatesOnly(true);

}  // namespace

BENCHMARK_MAIN();
