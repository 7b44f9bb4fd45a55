// `avatarbooth toon --front F --side S -o DIR`: Kitamura's two-view toon head from a photo pair, as a turntable strip.
#include "cli/commands.h"

#include "common/atomic_output.h"
#include "common/image_io.h"
#include "face/profile.h"
#include "face/silhouette.h"
#include "toon/toon_billboard.h"

#include <algorithm>
#include <iostream>

namespace avatarbooth {

void registerToonCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("toon", "Draw the visitor as a two-view toon and write a turntable strip of PNGs");
    struct Options {
        std::string front, side, background, out;
        int frames = 24;
        int colours = 6;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("--front", o->front, "Front photo")->required();
    cmd->add_option("--side", o->side, "Side photo (facing either way)")->required();
    cmd->add_option("--background", o->background, "The empty booth (better silhouettes)");
    cmd->add_option("-o,--output", o->out, "Output folder")->required();
    cmd->add_option("--frames", o->frames, "Frames from -90 to 90 degrees")->check(CLI::Range(2, 720))->capture_default_str();
    cmd->add_option("--colours", o->colours, "Flat colours of the drawing")->check(CLI::Range(2, 16))->capture_default_str();
    cmd->callback([o] {
        const cv::Mat front = readPhoto(o->front), side = readPhoto(o->side);
        const cv::Mat plate = o->background.empty() ? cv::Mat() : readPhoto(o->background);
        const SideAnalysis profile = analyzeSidePhoto(side, plate);
        // Both photos come from the same camera at the same height: the side photo's chin row cuts both masks to
        // the head.
        const int chin = static_cast<int>(profilePoint(profile.landmarks, "chin").y) + 1;
        cv::Mat frontMask = segmentPerson(front, plate), sideMask = profile.mask.clone();
        frontMask.rowRange(std::clamp(chin, 0, frontMask.rows), frontMask.rows).setTo(0);
        sideMask.rowRange(std::clamp(chin, 0, sideMask.rows), sideMask.rows).setTo(0);
        const toon::ToonModel model =
            toon::toonFromPhotos(front, frontMask, side, sideMask, profile.noseImageRight, o->colours);
        StagedDirectory dir(o->out, "turntable_000.png");
        toon::writeTurntable(model, dir.staging(), o->frames, {400, 440}, 1.0);
        dir.commit();
        std::cout << "toon: " << model.regionsA.regions.size() << " front regions, " << model.regionsB.regions.size()
                  << " side regions, " << model.pairs.size() << " matched\n"
                  << o->frames << " frames written to " << o->out << "\n";
    });
}

}  // namespace avatarbooth
