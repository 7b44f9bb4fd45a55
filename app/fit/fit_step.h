// The steps of one fit, in order, and each step's share of the progress bar: the typed seam between the pipeline,
// which runs them, and whoever shows its progress (the kiosk's processing screen).
#pragma once

#include <array>
#include <functional>

namespace avatarbooth {

enum class FitStep { ReadPhotos, FrontLandmarks, FrontSilhouette, SideProfile, HeadFit, Texture };

inline constexpr std::array<FitStep, 6> kFitSteps{FitStep::ReadPhotos,  FitStep::FrontLandmarks, FitStep::FrontSilhouette,
                                                  FitStep::SideProfile, FitStep::HeadFit,        FitStep::Texture};

// The step's name in fit.json's "stages", in the log and in the screens' strings ("stage.<name>").
constexpr const char* toString(FitStep step) {
    switch (step) {
        case FitStep::ReadPhotos: return "read_photos";
        case FitStep::FrontLandmarks: return "front_landmarks";
        case FitStep::FrontSilhouette: return "front_silhouette";
        case FitStep::SideProfile: return "side_profile";
        case FitStep::HeadFit: return "head_fit";
        case FitStep::Texture: return "texture";
    }
    return "unknown";
}

// The fraction of a booth's fit done when `step` starts: the steps' shares of the time `avatarbooth bench`
// measures. (A booth fits photos in memory: no ReadPhotos step.)
constexpr double progressAtStart(FitStep step) {
    switch (step) {
        case FitStep::ReadPhotos: return 0.0;
        case FitStep::FrontLandmarks: return 0.05;
        case FitStep::FrontSilhouette: return 0.2;
        case FitStep::SideProfile: return 0.3;
        case FitStep::HeadFit: return 0.4;
        case FitStep::Texture: return 0.5;
    }
    return 0.0;
}

// Told each step as it starts, on the fitting thread.
using FitStepListener = std::function<void(FitStep)>;

}  // namespace avatarbooth
