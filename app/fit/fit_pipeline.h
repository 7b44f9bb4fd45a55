// The photo-to-head pipeline as free of any booth as it can be: photos in, a fitted and textured head out, in
// memory (read photos -> front landmarks + silhouette -> side profile -> head fit -> texture). Writing the session
// folder is booth/session_folder.h's; the character is made from the outcome by reveal/character.
#pragma once

#include "fit/face/ear_locator.h"
#include "fit/face/side_eye.h"
#include "fit/face/hair_analysis.h"
#include "fit/face/landmarks68.h"
#include "fit/face/profile.h"
#include "fit/fit_error.h"
#include "fit/fit_step.h"
#include "fit/head/base_head.h"
#include "fit/head/head_fit.h"
#include "fit/head/photo_texture.h"
#include "fit/parts/avatar_parts.h"
#include "fit/parts/hair_part.h"

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include <atomic>
#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace avatarbooth {

struct FitSettings {
    std::filesystem::path landmarkModel = AVATARBOOTH_DEFAULT_DLIB_MODEL;
    HeadFitOptions head = defaultHeadFitOptions();
    PhotoTextureOptions texture;
    // Short hair trimmed to where the photos show hair (fit/parts/hair_part.h trimShortHairToPhotos).
    bool trimShortHair = true;
};

// The files one fit reads.
struct FitPhotoFiles {
    std::filesystem::path front, side, background;  // background may be empty
};

// How errors and fit.json name the photos: the files' paths, or (photos in memory) what they are.
struct FitPhotoNames {
    std::string front = "front photo", side = "side photo", background = "background plate";
    static FitPhotoNames of(const FitPhotoFiles& files) {
        return {files.front.string(), files.side.string(), files.background.string()};
    }
};

// Everything one fit produced, in memory.
struct FitOutcome {
    cv::Mat front, side, background;
    FaceLandmarks frontLandmarks;
    cv::Mat frontMask;
    std::map<std::string, cv::Point2d> sideLandmarks;
    bool sideNoseImageRight = true;
    cv::Mat sideMask;
    EarSpot sideEar;  // where the side photo shows the ear (fit/face/ear_locator.h)
    SideEyeSpot sideEye;  // where the side photo shows the near eye (fit/face/side_eye.h)
    // Texels of the face's sides where the front photo's hair was repainted with skin (skinOverHairBesideFace).
    int skinOverHairTexels = 0;
    // Texels round the bottom of the neck where the photos' clothes were repainted with skin (skinOverClothesOnNeck).
    int skinOverClothesTexels = 0;
    HairEstimate hair;  // the hair style, its colour, beard and moustache (fit/face/hair_analysis.h)
    // With a bob: how far over the brows the front photo shows the forehead, which the bob's fringe leaves clear
    // (fit/parts/hair_part.h foreheadShownMm); 0 otherwise.
    double foreheadShownMm = 0.0;
    // With short hair: how many of the hair part's vertices went where the photos show skin (fit/parts/hair_part.h
    // trimShortHairToPhotos); 0 otherwise.
    int hairTrimmedVertices = 0;
    // Of short hair, the vertices brought into the photos' outlines by more than 1 mm (pullShortHairIntoOutlines).
    int hairPulledInVertices = 0;
    // Long hair or a bob: the hair part's vertices moved back behind the side photo's hair edge beside the face
    // (fit/parts/hair_part.h tuckHairBehindTheFace); 0 otherwise.
    int hairTuckedVertices = 0;
    // With a bob: how far down the side photo shows the hair behind the head, and how the hair part's
    // length was scaled to it (fitHairLengthBehind); not measured otherwise.
    HairLength hairLength;
    // How big hair was stretched to the photos' outlines, band by band (fitHairToSilhouettes); empty otherwise.
    std::vector<HairStretch> hairStretch;
    HeadFit fit;
    PhotoTexture texture;
    // The avatar as shown and exported (fit/parts/avatar_part.h): the head (fit.mesh without what the proxies
    // replace, with texture.texture), then the base head's proxies placed on fit.mesh, coloured from the front photo
    // (partColours).
    std::vector<AvatarPart> parts;
    PartColours partColours;
    // The base head's named feature vertices where the fit put them (head-space millimetres).
    std::vector<std::pair<std::string, glm::dvec3>> featurePoints;
    RbfOptions rbf;                 // the warp the fit used
    double modelLoadSeconds = 0.0;  // of the pipeline that fitted it
    std::vector<std::pair<std::string, double>> stageSeconds;  // in order, named by toString(FitStep)
    // Processor time of each stage, all threads together (on a shared machine wall times vary with the load; this
    // is the work itself). Same order and names as stageSeconds.
    std::vector<std::pair<std::string, double>> stageCpuSeconds;
    std::vector<std::string> warnings;
};

// The front photo's analysis (landmarks, silhouette): fit()'s first two steps, which a booth runs as soon as the
// front photo is taken, while the visitor turns for the side photo.
struct FrontAnalysis {
    cv::Mat photo;  // the very image analysed: fit() uses the analysis only for a front photo sharing its pixels
    cv::Mat background;
    FaceLandmarks landmarks;
    cv::Mat mask;
    std::vector<std::pair<std::string, double>> stageSeconds, stageCpuSeconds;
};

// Cancels a fit from another thread (or a signal handler: it only reads an atomic flag). Default: never.
class CancelToken {
public:
    CancelToken() = default;
    explicit CancelToken(const std::atomic<bool>& cancelled) : cancelled_(&cancelled) {}
    bool cancelled() const { return cancelled_ != nullptr && cancelled_->load(std::memory_order_relaxed); }

private:
    const std::atomic<bool>* cancelled_ = nullptr;  // owned by the canceller, who keeps it alive during the fit
};

// Thrown by fit() and analyseFront() once their token is cancelled: between two steps, never in one.
struct FitCancelled : std::runtime_error {
    FitCancelled() : std::runtime_error("the fit was cancelled") {}
};

// How a fit is run: who hears of each step, and the token that cancels it.
struct FitControl {
    FitStepListener listener;
    CancelToken cancel;
};

class FitPipeline {
public:
    // Loads the landmark model (1-2 s) and builds the texture step's UV tables: build one pipeline and reuse it.
    explicit FitPipeline(FitSettings settings, const BaseHead& base = builtinBaseHead());
    ~FitPipeline();

    double modelLoadSeconds() const { return modelLoadSeconds_; }
    const BaseHead& baseHead() const { return base_; }
    const FitSettings& settings() const { return settings_; }
    // The loaded landmark detector, for the kiosk's preview guidance (not while a fit runs: one user at a time).
    const LandmarkDetector& detector() const { return *detector_; }

    // Another pipeline for another thread (batch runs): shares the loaded landmark model, the base head and the
    // texture tables, with a face detector of its own (see LandmarkDetector::sharingModel). Cheap: no loading.
    std::unique_ptr<FitPipeline> forAnotherThread() const;

    // Reads, analyses, fits and textures. Errors are FitErrors naming the photo they concern.
    FitOutcome fit(const FitPhotoFiles& files, const FitControl& control = {}) const;
    // The same on photos already in memory. `ahead`: the front photo's analysis made earlier (analyseFront), used
    // when it is of this front photo and background (else the front is analysed here).
    FitOutcome fit(const cv::Mat& front, const cv::Mat& side, const cv::Mat& background, const FitPhotoNames& names = {},
                   const FitControl& control = {}, const FrontAnalysis* ahead = nullptr) const;
    // The front photo's landmarks and silhouette alone (FitError NoFace about the front when there is no face).
    FrontAnalysis analyseFront(const cv::Mat& front, const cv::Mat& background, const FitPhotoNames& names = {},
                               const FitControl& control = {}) const;

private:
    FitPipeline(const FitPipeline& shareFrom, std::unique_ptr<LandmarkDetector> detector);

    FitSettings settings_;
    const BaseHead& base_;
    std::unique_ptr<LandmarkDetector> detector_;
    std::shared_ptr<const TextureTables> textureTables_;  // shared with the pipelines forAnotherThread() made
    std::shared_ptr<FrontalFaceCheck> frontalCheck_;      // likewise (it is thread-safe)
    std::shared_ptr<const EarTemplate> earTemplate_;      // likewise
    double modelLoadSeconds_ = 0.0;
};

// Drawings for a person to check the analysis: landmarks, silhouette outline, contour rays.
cv::Mat drawFrontOverlay(const FitOutcome& outcome);
cv::Mat drawSideOverlayWithRays(const FitOutcome& outcome);

}  // namespace avatarbooth
