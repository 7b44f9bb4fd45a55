// A software z-buffer of a mesh seen orthographically, at photo resolution: which surface each photo pixel shows,
// so that texturing can tell a surface point a photo sees from one hidden behind the nose, a lip or the chin.
#pragma once

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include <vector>

namespace avatarbooth {

// One vertex as a view sees it: pixel position (pixel centres at integer coordinates, as OpenCV) and depth in
// millimetres, growing towards the camera.
struct ViewVertex {
    float u = 0.0f, v = 0.0f, depth = 0.0f;
};

// The nearest depth (the largest) of any triangle covering each pixel centre; -infinity where none does.
// Orthographic, so depth interpolates linearly in the image. Triangles of either winding count (a fold of the
// warped mesh hides what is behind it like any other surface). Returns CV_32F of `size`.
cv::Mat rasteriseNearestDepth(const std::vector<ViewVertex>& vertices, const std::vector<glm::uvec3>& triangles,
                              cv::Size size);

}  // namespace avatarbooth
