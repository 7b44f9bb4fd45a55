// The mesh surface seen from texture space: for every texel, the 3-D point and normal it stands for.
// Texturing (photo projection) and the synthetic visitor's face paint both work texel by texel through this.
#pragma once

#include "fit/head/mesh.h"

#include <opencv2/core.hpp>

#include <vector>

namespace avatarbooth {

struct SurfaceTexels {
    cv::Mat position;  // CV_32FC3, head-space millimetres at the texel centre
    cv::Mat normal;    // CV_32FC3, unit normal (interpolated vertex normals)
    cv::Mat covered;   // CV_8U, 255 where a triangle covers the texel centre
};

// Which triangle covers each texel centre, and where in it: depends only on the UVs, so it is computed once per
// base head and reused for every fitted head of that topology.
struct TexelMap {
    cv::Size size;
    cv::Mat triangle;  // CV_32S, index into Mesh::triangles, -1 where no triangle covers the texel
    // Per triangle, the weights of its first two corners (the third's is 1 - both) as affine functions of the
    // texel's column and row: kept per triangle rather than per texel, which took 8 MB at 1024 texels.
    struct Weights {
        double c0 = 0.0, gx0 = 0.0, gy0 = 0.0, c1 = 0.0, gx1 = 0.0, gy1 = 0.0;
    };
    std::vector<Weights> weights;
    // The barycentric weights of the first two corners of triangle `tri` (>= 0) at texel (x, y)'s centre.
    cv::Vec2d barycentric(int tri, int x, int y) const {
        const Weights& w = weights[static_cast<std::size_t>(tri)];
        return {w.c0 + w.gx0 * x + w.gy0 * y, w.c1 + w.gx1 * x + w.gy1 * y};
    }
};

TexelMap mapTexels(const Mesh& mesh, cv::Size size);
// Positions and normals of the mesh at every mapped texel.
SurfaceTexels sampleSurfaceTexels(const Mesh& mesh, const std::vector<glm::dvec3>& normals, const TexelMap& map);

// Rasterises every triangle in UV space (texel centres at +0.5; the glTF convention, v down) and interpolates
// positions and the given per-vertex normals barycentrically.
SurfaceTexels sampleSurfaceTexels(const Mesh& mesh, const std::vector<glm::dvec3>& normals, cv::Size size);

// A texture painted texel by texel (BGR, the texels' size): `paint(position, normal)` gives the colour of each
// covered texel, in row order; the others stay black. The procedural textures (the character's flat colours, the
// synthetic visitor's face) are painted so.
template <typename Paint>
cv::Mat paintTexels(const SurfaceTexels& texels, Paint&& paint) {
    cv::Mat texture(texels.covered.size(), CV_8UC3, cv::Scalar(0, 0, 0));
    for (int y = 0; y < texture.rows; ++y)
        for (int x = 0; x < texture.cols; ++x) {
            if (!texels.covered.at<unsigned char>(y, x)) continue;
            const cv::Vec3f pf = texels.position.at<cv::Vec3f>(y, x);
            texture.at<cv::Vec3b>(y, x) = paint(glm::dvec3(pf[0], pf[1], pf[2]), texels.normal.at<cv::Vec3f>(y, x));
        }
    return texture;
}

// Extends the colours of covered texels a few texels into the uncovered ones, so that mipmapping and bilinear
// filtering never pull in the empty background along UV borders.
void padTextureBorders(cv::Mat& textureBgr, const cv::Mat& covered, int texels = 4);

}  // namespace avatarbooth
