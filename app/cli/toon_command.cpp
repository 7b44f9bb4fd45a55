// `avatarbooth toon --front F --side S -o DIR`: Kitamura's two-view toon head from a photo pair, as a turntable strip.
#include "cli/commands.h"

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/image_io.h"
#include "fit/face/landmarks68.h"
#include "reveal/toon/toon_billboard.h"
#include "reveal/toon/toon_correspondence.h"

#include <algorithm>
#include <chrono>
#include <iostream>

namespace avatarbooth {

void registerToonCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("toon", "Draw the visitor as a two-view toon and write a turntable strip of PNGs");
    struct Options {
        std::string front, side, background, out, correspondence, writeCorrespondence;
        std::string landmarkModel = AVATARBOOTH_DEFAULT_DLIB_MODEL;
        bool noLandmarks = false;
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
    cmd->add_option("--landmark-model", o->landmarkModel, "dlib's 68-point model (the front's eyes, brows and mouth)")
        ->capture_default_str();
    cmd->add_flag("--no-landmarks", o->noLandmarks, "Draw from the colours alone (no face parts from landmarks)");
    cmd->add_option("--correspondence", o->correspondence,
                    "Region pairs and outline points to use (an edited --write-correspondence file)");
    cmd->add_option("--write-correspondence", o->writeCorrespondence,
                    "Write the region pairs and outline points used (editable text, app/toon/toon_correspondence.h)");
    cmd->callback([o] {
        const cv::Mat front = readPhoto(o->front), side = readPhoto(o->side);
        const cv::Mat plate = o->background.empty() ? cv::Mat() : readPhoto(o->background);
        // The front's 68 points place the eyes, brows, nostrils and mouth as regions of their own; without a face
        // (or the model) the drawing comes from the colours alone, as the recipe has it.
        std::optional<std::array<cv::Point2d, 68>> points;
        if (!o->noLandmarks) {
            try {
                points = LandmarkDetector(o->landmarkModel).detect(front).points;
            } catch (const BoothError& e) {
                std::cerr << "toon: no face landmarks, drawing from the colours alone: " << e.what() << "\n";
            }
        }
        const auto drawStart = std::chrono::steady_clock::now();
        toon::ToonModel model = toon::toonFromPhotoPair(front, side, plate, o->colours, points);
        const double drawSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - drawStart).count();
        if (!o->correspondence.empty())
            toon::applyCorrespondence(model, toon::loadCorrespondence(o->correspondence), o->correspondence);
        if (!o->writeCorrespondence.empty())
            writeFileAtomically(o->writeCorrespondence, toon::formatCorrespondence(model));
        StagedDirectory dir(o->out, "turntable_000.png");
        toon::writeTurntable(model, dir.staging(), o->frames, {400, 440}, 1.0);
        dir.commit();
        std::cout << "toon: " << model.regionsA.regions.size() << " front regions, " << model.regionsB.regions.size()
                  << " side regions, " << model.pairs.size() << " matched, drawn in " << drawSeconds << " s"
                  << (points ? " (with the face's landmarks)" : "") << "\n"
                  << o->frames << " frames written to " << o->out << "\n";
    });
}

}  // namespace avatarbooth
