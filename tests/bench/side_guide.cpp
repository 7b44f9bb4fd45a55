// The side guide's analysis of one preview frame (PreviewAnalyser::observeSide, 972x720 as the simulated camera's
// preview stream gives it) for a MakeHuman visitor turned 90 degrees (a profile: outline, turn cues), 60 degrees
// with no nose on the outline (dlib's face detector runs and finds the face looking aside: "turn more") and 120
// degrees with none (it runs and finds nothing: "we can't see your face"). The frames without a profile cost the
// detector on top; the kiosk analyses the latest frame while the guide draws at the display's rate. Prints figures;
// never fails on speed.
#include "booth/guidance.h"
#include "fit/face/landmarks68.h"
#include "fit/head/base_head.h"
#include "render/mesh_renderer.h"
#include "sim/makehuman_visitor.h"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>

using namespace avatarbooth;

namespace {

struct Frame {
    cv::Mat bgr, plate;
};

// Seed 2 (nose to the image's left): its outline has no nose at 60 and at 120 degrees (TurnedProfiles).
const Frame& frame(int yaw) {
    static std::map<int, Frame> frames;
    if (const auto it = frames.find(yaw); it != frames.end()) return it->second;
    static const auto base = productBaseHead();
    static MeshRenderer renderer;
    MakeHumanVisitorOptions o;
    o.seed = 2;
    o.sideNoseImageRight = false;
    o.sideYawDeg = yaw;
    const MakeHumanVisitor v = makeMakeHumanVisitor(*base, renderer, o);
    return frames.emplace(yaw, Frame{v.photos.side, v.photos.background}).first->second;
}

const LandmarkDetector& detector() {
    static const LandmarkDetector d(AVATARBOOTH_DEFAULT_DLIB_MODEL);
    return d;
}

void BM_ObserveSide(benchmark::State& state) {
    const int yaw = static_cast<int>(state.range(0));
    const Frame& f = frame(yaw);
    PreviewAnalyser analyser(&detector(), {});
    SideObservation obs;
    for (auto _ : state) {
        obs = analyser.observeSide(f.bgr, f.plate);
        benchmark::DoNotOptimize(obs);
    }
    state.SetLabel(cv::format("yaw %d: hint %s%s", yaw, toString(sideHint(obs)),
                              obs.faceLooked ? " (dlib's detector ran)" : ""));
}
BENCHMARK(BM_ObserveSide)->Arg(90)->Arg(60)->Arg(120)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
