// Where the ear is in a side photo: the base head's ear sits where proportions put it, and on a real visitor it is
// often 10-30 mm off, so that the side photo's ear was painted on the scalp or the neck beside the mesh's ear.
#pragma once

#include <opencv2/core.hpp>

#include <vector>

namespace avatarbooth {

struct ProfilePoint;

// A head's ear as a side photo shows it, facing image-right (fit/head/ears.h makes it from the base head).
struct EarTemplate {
    cv::Mat shade;              // CV_32F, its light and shade
    cv::Mat mask;               // CV_8U, 255 on the ear and 4 mm round it
    double mmPerPixel = 0.0;
    cv::Point2d centre;         // the ear's middle (its vertices' mean), template pixels
    double noseTipToTop = 0.0;  // the head's V: the nose tip's height under the top of the head (mm)
    // Where the ear's middle lies from the nose tip, in V.
    double behindNoseTip = 0.0, aboveNoseTip = 0.0;
    bool empty() const { return shade.empty(); }
};

struct EarSpot {
    bool found = false;
    cv::Point2d centre;   // the ear's middle, in the photo as taken (pixels): the best place, found or not
    double score = 0.0;   // how well the photo's edges run along the template's there (-1..1; 0: at random)
    double scale = 0.0;   // the ear's size against the template's, by the photo's V
};

// Lengths in V, the nose tip's height under the top of the head in the photo (hair included: about 140-170 mm).
struct EarLocatorOptions {
    // How far from the template's own place the ear's middle is searched (a visitor turned 20 degrees from the
    // profile moves the ear by about 0.15 V, and heads differ), the sizes tried against the template's at the
    // photo's V, and the least score (FRMDB's ears 0.18-0.29, the cheek or hair where the ear is hidden 0.10-0.13).
    double searchAlong = 0.3, searchUpDown = 0.25;
    std::vector<double> scales{0.7, 0.8, 0.9, 1.0, 1.1};
    double minScore = 0.14;
};

// Finds the ear in a side photo whose profile landmarks are known (noseImageRight: which way the face points): where
// the photo's edges run as the template's do (ear_locator.cpp). hair: the photo's hair pixels (CV_8U, 255 on hair;
// empty: none known): a window mostly on hair is no ear. Not found: an ear under hair, or no template.
EarSpot locateEar(const cv::Mat& bgr, const cv::Mat& mask, const cv::Mat& hair,
                  const std::vector<ProfilePoint>& landmarks, bool noseImageRight, const EarTemplate& ear,
                  const EarLocatorOptions& options = {});

}  // namespace avatarbooth
