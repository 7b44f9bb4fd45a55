// The person's silhouette in a booth photo (head, hair, neck, shoulders), with or without a background plate.
#pragma once

#include <opencv2/core.hpp>

#include <vector>

namespace avatarbooth {

// Segments the person in a BGR photo. Returns a CV_8U mask of the photo's size, 255 on the person (head, hair,
// neck, shoulders) and 0 elsewhere: one 8-connected component, no holes, edges smoothed.
//
// backgroundPlate: the empty booth (BGR, same size) or empty. With a plate the first guess is the colour
// difference against it; without one, the background's colours are learned from the top, left and right image
// borders (the person is assumed to touch at most the bottom border) and the person's colours from the head.
// Both then alternate a colour-model relabelling with cleaning (largest component, holes filled) on a copy at
// about 480 px, and relabel a band around the coarse edge at full resolution (see silhouette.cpp).
// Without a plate the person's colours are seeded from warm colours (skin; brown, black, blond, red hair) unlike
// the border: clothes in cold colours are found only where they differ clearly from the backdrop (a teal jumper on
// a blue cloth is left out; a lit fold of the cloth next to the face is then also kept out, which matters more for
// the profile). With a plate, clothes of any colour are found.
// headHint: a box on the face (the front detector's box, or a profile-face box) or empty; when given, the
// component overlapping it is the person and its colours seed the person's colour model.
// Throws BoothError(BadInput) for an empty or non-BGR image or a plate of another size, BoothError(NoFace)
// when nothing that could be a person stands out from the background.
cv::Mat segmentPerson(const cv::Mat& bgr, const cv::Mat& backgroundPlate = cv::Mat(), cv::Rect headHint = cv::Rect());

// The outer outline of the largest component of a CV_8U mask (pixel centres, CHAIN_APPROX_NONE); empty if none.
std::vector<cv::Point> largestOutline(const cv::Mat& mask);

// Intersection over union of two CV_8U masks (non-zero = inside); 1 when both are empty.
double maskIoU(const cv::Mat& a, const cv::Mat& b);

}  // namespace avatarbooth
