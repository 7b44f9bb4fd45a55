// What the kiosk's process holds before it does any work of its own: the libraries it links, one GL context with one
// textured mesh drawn through it (the driver and, under llvmpipe, LLVM compiling the shaders) and dlib's face detector
// and 68-point model. Prints the RSS after each step, split into anonymous memory and library (file) pages, and the
// libraries holding the most pages. The kiosk's peak RSS (`avatarbooth run` prints it; issue 3's target is 300 MB)
// minus this floor is the memory the booth's own work takes. Prints figures; never fails on size.
// Usage: bench_memory_floor [landmark model]   (default: Debian's libdlib-data model)
#include "drivers/display/headless_egl.h"
#include "fit/face/landmarks68.h"
#include "fit/head/base_head.h"
#include "kiosk/kiosk.h"
#include "render/mesh_renderer.h"
#include "sim/process_figures.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

using namespace avatarbooth;

namespace {

void step(const char* what) {
    const ProcessFigures f = readProcessFigures();
    std::printf("memory floor: %-48s rss %4.0f MB (anonymous %4.0f, library pages %4.0f)\n", what, f.rssMegabytes,
                f.anonRssMegabytes, f.fileRssMegabytes);
}

// Resident pages per mapped file, largest first.
void topLibraries(int count) {
    std::vector<std::pair<double, std::string>> sorted;
    for (const auto& [name, megabytes] : residentByMapping())
        if (!name.empty() && name.front() == '/') sorted.emplace_back(megabytes, name);
    std::sort(sorted.rbegin(), sorted.rend());
    for (int i = 0; i < count && i < static_cast<int>(sorted.size()); ++i)
        std::printf("memory floor:   %5.1f MB  %s\n", sorted[static_cast<std::size_t>(i)].first,
                    sorted[static_cast<std::size_t>(i)].second.c_str());
}

}  // namespace

int main(int argc, char** argv) {
    tuneAllocatorForKiosk();  // as the kiosk does before anything else
    step("libraries loaded");
    {
        HeadlessEglContext context;
        step("+ a GL context");
        MeshRenderer renderer(context, MeshRendererOptions{.maxSamples = 1, .depth = false});
        const BaseHead& head = builtinBaseHead();
        cv::Mat texture(256, 256, CV_8UC3, cv::Scalar(90, 120, 200));
        renderer.upload(head.mesh, texture);
        cv::Mat bgra;
        renderer.renderBgra(RenderCamera::orthographic({0, 0, 400}, {0, 0, 0}, {0, 1, 0}, 1.0, 64, 64), bgra);
        step("+ the base head drawn once (shaders compiled)");
        const LandmarkDetector detector(argc > 1 ? argv[1] : AVATARBOOTH_DEFAULT_DLIB_MODEL);
        step("+ dlib's face detector and 68-point model");
        {
            // What the kiosk's session writer adds for its previews: its own GL context (on its own thread in the
            // kiosk) with the fit's 1024-texel texture, drawn at 512 with 2 samples.
            MeshRenderer writer(MeshRendererOptions{.maxSamples = 2, .depth = false});
            writer.upload(head.mesh, cv::Mat(1024, 1024, CV_8UC3, cv::Scalar(90, 120, 200)));
            cv::Mat preview;
            writer.renderBgra(RenderCamera::orthographic({0, 0, 400}, {0, 0, 0}, {0, 1, 0}, 1.0, 512, 512), preview);
            step("+ a second context drawing a 1024 texture at 512");
        }
        step("- the second context again");
        std::printf("memory floor: peak %.0f MB; the libraries holding the most pages:\n",
                    readProcessFigures().peakRssMegabytes);
        topLibraries(6);
    }
    return 0;
}
