// Likeness against a real head scan, as the issue measures it: the Lee Perry-Smith scan's front render (yaw 0) with
// each of its side renders (yaw +90, -90) fitted with the product's base head, and the face region's distance from
// the scan measured by ../shared/tools/likeness/measure.py (similarity from the 68 landmarks, then ICP with scale;
// RMS of the scan-to-fit surface distance at 46.7 mm per scan unit), with the unfitted MakeHuman head beside it.
// folds.py counts the fit's triangles turned over against the base head. The figures are printed; the test holds
// the fit to what must be true of any fit worth having: nearer the scan than no photo at all, and without a fold.
// (Debian's /usr/bin/python3 with python3-numpy and python3-scipy: another python3 on the PATH may lack them.)
#include "test_paths.h"

#include "booth/session_folder.h"
#include "fit/export/glb.h"
#include "fit/face/hair_analysis.h"
#include "fit/fit_pipeline.h"
#include "fit/head/base_head.h"
#include "render/mesh_renderer.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>

namespace fs = std::filesystem;
using namespace avatarbooth;

namespace {

fs::path likenessTools() { return test::sharedData().parent_path() / "tools" / "likeness"; }

int run(const std::string& command) {
    std::printf("$ %s\n", command.c_str());
    std::fflush(stdout);
    return std::system(command.c_str());
}

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

}  // namespace

TEST(Likeness, ScanFaceRegionNearerThanTheUnfittedHeadAndNoFolds) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    const fs::path baseDir = findMakeHumanBaseHead();
    if (baseDir.empty()) GTEST_SKIP() << "the MakeHuman base head was not built";
    if (!fs::is_regular_file(likenessTools() / "measure.py")) GTEST_SKIP() << "no " << likenessTools() / "measure.py";
    if (run("/usr/bin/python3 -c 'import numpy, scipy' 2>/dev/null") != 0) GTEST_SKIP() << "python3-numpy/-scipy missing";

    const fs::path scan = test::sharedData() / "scan_lee_perry_smith";
    const auto base = productBaseHead();
    const FitPipeline pipeline{FitSettings{}, *base};
    MeshRenderer renderer;
    const fs::path work = test::scratchDir("likeness");
    std::string fits, foldsArgs;
    for (const char* side : {"+090", "-090"}) {
        const FitPhotoFiles inputs{scan / "renders" / "LeePerrySmith_yaw+000_rgb.png",
                                   scan / "renders" / (std::string("LeePerrySmith_yaw") + side + "_rgb.png"), {}};
        const fs::path out = work / (std::string("side") + side);
        const FitOutcome outcome = pipeline.fit(inputs);
        writeSessionFolder(outcome, {inputs}, out, renderer);
        // The scan's head is bald: its crown's shading is no hair (fit/face/hair_analysis.h).
        EXPECT_EQ(outcome.hair.style, HairStyle::None) << side << ": " << toString(outcome.hair.style);
        fits += " --fit " + quoted(out / "avatar.glb") + " --name fit" + side;
        // folds.py compares a head of the base head's topology: avatar.glb's head lost its eyeballs to the eye part.
        writeGlb(out / "head_topology.glb", outcome.fit.mesh, outcome.texture.texture);
        foldsArgs += " " + quoted(out / "head_topology.glb");
    }
    const fs::path json = work / "measure.json";
    ASSERT_EQ(run("/usr/bin/python3 " + quoted(likenessTools() / "measure.py") + " --scan " + quoted(scan / "LeePerrySmith.obj") +
                  " --scan-mm-per-unit 46.7 --scan-landmarks " + quoted(likenessTools() / "lps_landmarks68.txt") + fits +
                  " --fit " + quoted(baseDir / "base_head.glb") + " --name base > " + quoted(json)),
              0);
    std::ifstream in(json);
    const nlohmann::json m = nlohmann::json::parse(in);
    const double baseRms = m.at("fits").at("base").at("rms_mm").get<double>();
    for (const char* name : {"fit+090", "fit-090"}) {
        const auto& f = m.at("fits").at(name);
        std::printf("likeness: %s face-region RMS %.2f mm, median %.2f mm (unfitted MakeHuman head %.2f mm; eos fitted "
                    "1.93 mm, the issue's goal under 1.5 mm)\n",
                    name, f.at("rms_mm").get<double>(), f.value("median_mm", 0.0), baseRms);
        EXPECT_LT(f.at("rms_mm").get<double>(), baseRms) << name;
    }
    // folds.py prints the total of triangles turned over against the base head.
    const fs::path folds = work / "folds.txt";
    ASSERT_EQ(run("/usr/bin/python3 " + quoted(likenessTools() / "folds.py") + " " + quoted(baseDir / "base_head.glb") + foldsArgs +
                  " > " + quoted(folds)),
              0);
    std::ifstream f(folds);
    int total = -1;
    f >> total;
    std::printf("likeness: folds.py: %d triangles turned over\n", total);
    EXPECT_EQ(total, 0);
}
