// Texturing the fitted head from the two photos (METHODS §1 step 6, with §4's multi-view practice): every texel
// takes the colour of both photos where it projects, weighted by how squarely each photo sees the surface there.
#pragma once

#include "head/head_fit.h"

#include <opencv2/core.hpp>

namespace avatarbooth {

struct PhotoTextureOptions {
    int size = 1024;
    // Weight exponent on the cosine between surface normal and view direction (higher = stricter: each texel
    // comes more from the photo that faces it; 2 blends a soft seam).
    double angleStrictness = 2.0;
};

struct PhotoTexture {
    cv::Mat texture;    // BGR, size x size, in the mesh's UV layout
    double seenFraction = 0.0;  // share of the head's texels some photo saw (the rest was filled in)
};

// front/side: the photos as taken; the masks: their silhouettes. The side photo is used for both sides of the
// head (mirrored for the side it did not see). Texels no photo saw (the back of the head) are filled from their
// surroundings by a pull-push (coarse-to-fine) fill, so they continue the hair and skin colours around them.
PhotoTexture textureFromPhotos(const Mesh& fitted, const HeadFit& fit, const cv::Mat& front, const cv::Mat& frontMask,
                               const cv::Mat& side, const cv::Mat& sideMask, const PhotoTextureOptions& options = {});

// Fills texels where weight == 0 from the others, coarse to fine (pull-push). colour: CV_32FC3, weight: CV_32F.
void pullPushFill(cv::Mat& colour, cv::Mat& weight);

}  // namespace avatarbooth
