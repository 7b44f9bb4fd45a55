// What a fit writes for the character maker (Narita): character.json (Narita's proportions and slider values)
// and character.glb (the stylised character head), made from the fit's front photo analysis.
#pragma once

#include "reveal/character/character_head.h"
#include "fit/fit_pipeline.h"
#include "fit/head/head_fit.h"

#include <opencv2/core.hpp>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace avatarbooth {

struct CharacterOutputs {
    std::string json;                   // character.json, pretty-printed
    std::string glb;                    // character.glb bytes
    std::vector<std::string> warnings;  // for fit.json (ears estimated, temples cut by the frame, ...)
    CharacterHead head;                 // the head itself (mesh and painted texture), for the kiosk's reveal
    double makeSeconds = 0.0;           // how long making it took (fit.json's "character" stage)
};

// The side photo's ear hole carried into the front photo through the fit's shared heights (its x is the head's
// midline); nothing when the side analysis has no ear hole.
std::optional<cv::Point2d> earHoleInFrontPhoto(const HeadFit& fit, const std::map<std::string, cv::Point2d>& sideLandmarks);

// Maps the 21 points, computes the proportions, builds the character head from `base` with colours taken from
// the photo, and encodes both files. Errors are BoothErrors (NoFace when the silhouette does not cover the eyes).
CharacterOutputs makeCharacterOutputs(const cv::Mat& frontPhoto, const std::array<cv::Point2d, 68>& landmarks,
                                      const cv::Mat& frontMask, std::optional<cv::Point2d> earHole,
                                      const BaseHead& base, const CharacterSettings& settings = {});
// The same from a fit (its front photo, landmarks and silhouette, and the side photo's ear hole).
CharacterOutputs makeCharacterOutputs(const FitOutcome& outcome, const BaseHead& base,
                                      const CharacterSettings& settings = {});

}  // namespace avatarbooth
