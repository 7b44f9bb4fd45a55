// Where the near eye is in a side photo. Visitors seldom turn exactly 90 degrees: turned 15 degrees towards the
// camera, the eye lies 10-20 mm further behind the nose's outline than a profile puts it, and the side photo,
// projected onto the head as a profile, painted a second eye onto the temple (FRMDB 005). The texture reads the
// side photo shifted by the difference (HeadFit::eyeLeftMm).
#pragma once

#include <opencv2/core.hpp>

#include <vector>

namespace avatarbooth {

struct ProfilePoint;

struct SideEyeSpot {
    bool found = false;
    cv::Point2d centre;     // the eye's middle in the photo as taken (pixels)
    double contrast = 0.0;  // how much darker than the cheek round it (grey levels, smoothed over the eye's size)
};

// Lengths in V, the nose tip's height under the top of the head in the photo (hair included: about 140-170 mm).
struct SideEyeOptions {
    // Where the eye is searched: rows from `above` over the nasion to `below` under it; behind the face's outline on
    // each row from `nearest` to `furthest` (a profile puts the eye about 0.1 V behind it, 60 degrees from the front
    // about 0.2 V).
    double above = 0.06, below = 0.12;
    double nearest = 0.03, furthest = 0.32;
    // The darkness is smoothed over about the eye's size seen from the side (its lashes, iris and the shadow under
    // the brow together), so that one dark pore or a strand of hair does not win.
    double sigma = 0.02;
    // The least contrast that counts (grey levels): FRMDB's eyes 49-119; under 25, a hidden eye leaves a shadow or
    // a strand of hair (FRMDB 007's left profile, 18).
    double minContrast = 25.0;
};

// Finds the near eye in a side photo whose profile landmarks are known (noseImageRight: which way the face
// points): the darkest eye-sized spot behind the nose bridge's outline, in the band round the nasion's height.
// hair: the photo's hair pixels (CV_8U, 255 on hair; empty: none known): the large hair regions (a fringe, hair
// over the temple) do not count; the brows' and lashes' small ones do, as part of the eye.
SideEyeSpot locateSideEye(const cv::Mat& bgr, const cv::Mat& mask, const cv::Mat& hair,
                          const std::vector<ProfilePoint>& landmarks, bool noseImageRight,
                          const SideEyeOptions& options = {});

}  // namespace avatarbooth
