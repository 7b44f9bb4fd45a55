// The colours of the visitor's eyes and brows, measured in the front photo at dlib's landmarks, for the parts that
// take them (avatar_parts.h).
#pragma once

#include "fit/face/landmarks68.h"
#include "fit/parts/avatar_parts.h"

#include <opencv2/core.hpp>

#include <optional>

namespace avatarbooth {

// The iris' colour (BGR, 0..255): inside each eye's outline (landmarks 36-41, 42-47), the pixels that are neither
// the white of the eye (bright and grey), nor the pupil, lashes and lid shadows (the darkest), nor a highlight (the
// brightest); the median of both eyes' such pixels. Nothing when the eyes are too small or closed in the photo.
std::optional<cv::Vec3d> measureIrisColour(const cv::Mat& frontBgr, const FaceLandmarks& landmarks);

// The brows' colour (BGR): along the brow landmarks (17-21, 22-26) in a band as thick as a brow, the darkest quarter
// of the pixels (the hairs, not the skin between them), their median. Nothing when the band leaves the photo.
std::optional<cv::Vec3d> measureBrowColour(const cv::Mat& frontBgr, const FaceLandmarks& landmarks);

// Both, keyed by the part they colour ("eyes", "eyebrows").
PartColours measurePartColours(const cv::Mat& frontBgr, const FaceLandmarks& landmarks);

}  // namespace avatarbooth
