// The whole photo-to-head pipeline, as `avatarbooth fit` (and later the kiosk and batch runs) use it:
// read photos -> front landmarks + silhouette -> side profile -> fit -> texture -> previews -> session folder.
#pragma once

#include "reveal/character/character_outputs.h"
#include "fit/face/landmarks68.h"
#include "fit/head/base_head.h"
#include "fit/head/head_fit.h"
#include "fit/head/photo_texture.h"
#include "render/mesh_renderer.h"

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace avatarbooth {

struct FitSettings {
    std::filesystem::path landmarkModel = AVATARBOOTH_DEFAULT_DLIB_MODEL;
    HeadFitOptions head = defaultHeadFitOptions();
    PhotoTextureOptions texture;
    int previewSize = 512;
    // The character avatar (issue 6): character.json + character.glb in every session when enabled ([character]).
    bool characterEnabled = true;
    CharacterSettings character;
};

struct FitInputs {
    std::filesystem::path front, side, background;  // background may be empty
};

// Everything one fit produced, in memory.
struct FitOutcome {
    cv::Mat front, side, background;
    FaceLandmarks frontLandmarks;
    cv::Mat frontMask;
    std::map<std::string, cv::Point2d> sideLandmarks;
    bool sideNoseImageRight = true;
    cv::Mat sideMask;
    HeadFit fit;
    PhotoTexture texture;
    std::vector<std::pair<std::string, double>> stageSeconds;  // in order
    // Processor time of each stage, all threads together (on a shared machine wall times vary with the load; this
    // is the work itself). Same order and names as stageSeconds.
    std::vector<std::pair<std::string, double>> stageCpuSeconds;
    std::vector<std::string> warnings;
};

// The front photo's analysis (landmarks, silhouette): fit()'s first two stages, which a booth runs as soon as the
// front photo is taken, while the visitor turns for the side photo.
struct FrontAnalysis {
    cv::Mat photo;  // the very image analysed: fit() uses the analysis only for a front photo sharing its pixels
    cv::Mat background;
    FaceLandmarks landmarks;
    cv::Mat mask;
    std::vector<std::pair<std::string, double>> stageSeconds, stageCpuSeconds;
};

// Told the name of each stage as it starts ("front_landmarks", "front_silhouette", "side_profile", "head_fit",
// "texture"), from the fitting thread: the kiosk shows progress with it.
using StageListener = std::function<void(const std::string& stage)>;

class FitPipeline {
public:
    // Loads the landmark model (1-2 s) and builds the texture step's UV tables: build one pipeline and reuse it.
    explicit FitPipeline(FitSettings settings, const BaseHead& base = builtinBaseHead());
    ~FitPipeline();

    double modelLoadSeconds() const { return modelLoadSeconds_; }
    const BaseHead& baseHead() const { return base_; }
    // The loaded landmark detector, for the kiosk's preview guidance (not while a fit runs: one user at a time).
    const LandmarkDetector& detector() const { return *detector_; }

    // Another pipeline for another thread (batch runs): shares the loaded landmark model, the base head and the
    // texture tables, with a face detector of its own (see LandmarkDetector::sharingModel). Cheap: no loading.
    std::unique_ptr<FitPipeline> forAnotherThread() const;

    // Reads, analyses, fits and textures. Errors are BoothErrors naming the photo they concern.
    FitOutcome fit(const FitInputs& inputs) const;
    // The same on photos already in memory (names are used in error messages).
    // `ahead`: the front photo's analysis made earlier (analyseFront), used when it is of this front photo and
    // background (else the front is analysed here).
    FitOutcome fit(const cv::Mat& front, const cv::Mat& side, const cv::Mat& background,
                   const FitInputs& names = {}, const StageListener& listener = {},
                   const FrontAnalysis* ahead = nullptr) const;
    // The front photo's landmarks and silhouette alone (BoothError NoFace naming the photo when there is no face).
    FrontAnalysis analyseFront(const cv::Mat& front, const cv::Mat& background, const FitInputs& names = {},
                               const StageListener& listener = {}) const;

    // Writes the session folder atomically: it is complete, or absent (an earlier result stays as it was).
    // Returns the paths of what was written. The renderer makes the previews. `character`: the character outputs
    // made beforehand with makeCharacter (the kiosk shows the head before the folder is written); made here when
    // null.
    std::vector<std::filesystem::path> write(const FitOutcome& outcome, const FitInputs& inputs,
                                             const std::filesystem::path& out, MeshRenderer& renderer,
                                             const CharacterOutputs* character = nullptr) const;
    // The character maker's outputs for a fit (character.json, character.glb and the head itself); empty when the
    // character is off ([character] enabled = false).
    CharacterOutputs makeCharacter(const FitOutcome& outcome) const;

private:
    FitPipeline(const FitPipeline& shareFrom, std::unique_ptr<LandmarkDetector> detector);

    FitSettings settings_;
    const BaseHead& base_;
    std::unique_ptr<LandmarkDetector> detector_;
    double modelLoadSeconds_ = 0.0;
};

// Drawings for a person to check the analysis: landmarks, silhouette outline, contour rays.
cv::Mat drawFrontOverlay(const FitOutcome& outcome);
cv::Mat drawSideOverlayWithRays(const FitOutcome& outcome);

}  // namespace avatarbooth
