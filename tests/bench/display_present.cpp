// Presenting a 1280x720 frame: the headless display's copy, the CPU turn-and-fit for a portrait panel, and the
// kms/window quad presenter (texture upload + one quad) under the offscreen EGL context (llvmpipe here), exact
// size and scaled. Prints figures; never fails on speed.
#include "drivers/display/display_geometry.h"
#include "drivers/display/headless_display.h"
#include "drivers/display/headless_egl.h"
#include "drivers/display/quad_presenter.h"

#include <GLES3/gl3.h>
#include <benchmark/benchmark.h>

#include <memory>

using namespace avatarbooth;

namespace {

cv::Mat frame(cv::Size s) {
    cv::Mat m(s, CV_8UC3);
    cv::randu(m, cv::Scalar::all(0), cv::Scalar::all(256));
    return m;
}

void BM_HeadlessPresent(benchmark::State& state) {
    HeadlessDisplay display(DisplaySettings{});
    const cv::Mat f = frame(display.size());
    for (auto _ : state) display.present(f);
    state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HeadlessPresent)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_ComposeForPortraitPanel(benchmark::State& state) {
    const cv::Mat f = frame({720, 1280});
    for (auto _ : state) benchmark::DoNotOptimize(composeForPanel(f, {1280, 720}, Rotation::R90));
}
BENCHMARK(BM_ComposeForPortraitPanel)->Unit(benchmark::kMillisecond)->UseRealTime();

// The quad presenter into a framebuffer of `panel`; glFinish so the figure includes the drawing itself.
void presenterBench(benchmark::State& state, cv::Size image, cv::Size panel, Rotation r) {
    std::unique_ptr<HeadlessEglContext> context;
    try {
        context = std::make_unique<HeadlessEglContext>();
    } catch (const std::exception& e) {
        state.SkipWithError(e.what());
        return;
    }
    GLuint rb = 0, fbo = 0;
    glGenRenderbuffers(1, &rb);
    glBindRenderbuffer(GL_RENDERBUFFER, rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, panel.width, panel.height);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);
    {
        QuadPresenter presenter;
        const cv::Mat f = frame(image);
        for (auto _ : state) {
            presenter.draw(f, panel, r);
            glFinish();
        }
    }
    glDeleteFramebuffers(1, &fbo);
    glDeleteRenderbuffers(1, &rb);
    state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
    state.SetLabel(context->renderer());
}

void BM_QuadPresenterExact(benchmark::State& state) { presenterBench(state, {1280, 720}, {1280, 720}, Rotation::R0); }
BENCHMARK(BM_QuadPresenterExact)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_QuadPresenterPortrait(benchmark::State& state) {
    presenterBench(state, {720, 1280}, {1280, 720}, Rotation::R90);
}
BENCHMARK(BM_QuadPresenterPortrait)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_QuadPresenterScaled(benchmark::State& state) {
    presenterBench(state, {1280, 720}, {1920, 1080}, Rotation::R0);
}
BENCHMARK(BM_QuadPresenterScaled)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
