// `avatarbooth fit --front F --side S [--background B] -o OUT/`: one photo pair to a session folder.
#include "cli/commands.h"

#include "booth/session_folder.h"
#include "common/error.h"
#include "config/booth_config.h"
#include "fit/fit_pipeline.h"
#include "render/mesh_renderer.h"
#include "reveal/character/character_outputs.h"

#include <iostream>
#include <optional>

namespace avatarbooth {

void registerFitCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("fit", "Fit a textured 3-D head to a front and a side photo");
    struct Options {
        FitPhotoFiles inputs;
        std::string out;
        std::string kernel = "ntt";
        double unitMm = 23.0;
        std::string model = AVATARBOOTH_DEFAULT_DLIB_MODEL;
        std::string baseMesh, baseFeatures;
        int textureSize = 1024;
        std::string config;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("--front", o->inputs.front, "Front photo (JPEG or PNG)")->required();
    cmd->add_option("--side", o->inputs.side, "Side (profile) photo; the nose may point either way")->required();
    cmd->add_option("--background", o->inputs.background, "Photo of the empty booth (improves the silhouettes)");
    cmd->add_option("-o,--output", o->out, "Output session folder (written completely or not at all)")->required();
    cmd->add_option("--kernel", o->kernel, "RBF kernel: ntt (the paper's 1/(r+1)), tps, gaussian")->capture_default_str();
    cmd->add_option("--rbf-unit-mm", o->unitMm, "Length of one unit of r, in mm")->capture_default_str();
    cmd->add_option("--landmark-model", o->model, "dlib 68-point shape predictor (iBUG 300-W: non-commercial terms)")
        ->capture_default_str();
    cmd->add_option("--base-mesh", o->baseMesh, "Your own base head (glb with UVs) instead of the built-in one");
    cmd->add_option("--base-features", o->baseFeatures, "Feature file of --base-mesh (see make-base-head)");
    cmd->add_option("--texture-size", o->textureSize, "Texture size in texels")->capture_default_str()->check(CLI::Range(256, 4096));
    cmd->add_option("--config", o->config, "Booth configuration: its [fit] table gives the defaults of the options above");
    cmd->callback([o, cmd] {
        // The config's [fit] and [character] tables first; each option given on the command line then wins over it.
        BoothConfig config;
        if (!o->config.empty()) config = loadBoothConfig(o->config);
        const FitConfig& fromFile = config.fit;
        FitSettings settings = fromFile.settings;
        const auto given = [&](const char* option) { return cmd->count(option) > 0; };
        if (given("--kernel")) {
            try {
                settings.head.rbf.kernel = parseRbfKernel(o->kernel);
            } catch (const std::invalid_argument& e) {
                throw BoothError(ErrorKind::BadConfig, "--kernel", e.what());
            }
        }
        if (given("--rbf-unit-mm")) {
            if (!(o->unitMm > 0.0)) throw BoothError(ErrorKind::BadConfig, "--rbf-unit-mm", "must be positive");
            settings.head.rbf.unitMm = o->unitMm;
        }
        if (given("--landmark-model") || o->config.empty()) settings.landmarkModel = o->model;
        if (given("--texture-size") || o->config.empty()) settings.texture.size = o->textureSize;
        if (!given("--base-mesh") && !given("--base-features")) {
            o->baseMesh = fromFile.baseMesh.string();
            o->baseFeatures = fromFile.baseFeatures.string();
        }
        if (o->baseMesh.empty() != o->baseFeatures.empty())
            throw BoothError(ErrorKind::BadConfig, "--base-mesh/--base-features", "give both or neither");
        std::unique_ptr<BaseHead> custom;
        if (!o->baseMesh.empty()) custom = std::make_unique<BaseHead>(loadBaseHead(o->baseMesh, o->baseFeatures));
        const auto product = custom ? nullptr : productBaseHead();
        const BaseHead& base = custom ? *custom : *product;
        const FitPipeline pipeline(settings, base);
        const FitOutcome outcome = pipeline.fit(o->inputs);
        std::optional<CharacterOutputs> character;
        if (config.character.enabled) character = makeCharacterOutputs(outcome, base, config.character.settings);
        MeshRenderer renderer;
        writeSessionFolder(outcome, {o->inputs, character ? &*character : nullptr, fromFile.previewSize}, o->out,
                           renderer);
        for (const auto& w : outcome.warnings) std::cerr << "avatarbooth: warning: " << w << "\n";
        double seconds = 0.0;
        for (const auto& [name, s] : outcome.stageSeconds) seconds += s;
        std::cout << "avatar written to " << (std::filesystem::path(o->out) / "avatar.glb").string() << "\n"
                  << "previews: " << (std::filesystem::path(o->out) / "preview_front.png").string() << ", preview_side.png, "
                  << "preview_three_quarter.png\n"
                  << "overlays: front_overlay.jpg, side_overlay.jpg; report: fit.json, landmarks.json\n"
                  << "fit took " << static_cast<int>(seconds * 1000.0) << " ms (model loading "
                  << static_cast<int>(pipeline.modelLoadSeconds() * 1000.0) << " ms apart)\n";
    });
}

}  // namespace avatarbooth
