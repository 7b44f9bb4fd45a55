// The avatar's parts on a fitted head (avatar_part.h): the head itself, then the base head's proxies placed through
// their bindings and coloured from the photo.
#pragma once

#include "fit/head/base_head.h"
#include "fit/parts/avatar_part.h"
#include "fit/parts/head_proxy.h"

#include <opencv2/core.hpp>

#include <limits>
#include <map>
#include <string>
#include <vector>

namespace avatarbooth {

// A colour (BGR, 0..255) per part name, measured from the photos (part_colours.h): "eyes" the iris, "eyebrows" the
// brows. A part with a tint mask and no colour here keeps its texture's own.
using PartColours = std::map<std::string, cv::Vec3d>;

// The head (named "head": `fittedHead` without the triangles the proxies replace, with `headTexture`), then each of
// `base.proxies` placed on `fittedHead` (which has the base head's topology), tinted where it has a tint mask and
// `colours` has its name. The hair styles are left out: they are alternatives, and the fit places the one it chose
// (hair_part.h).
std::vector<AvatarPart> placeParts(const BaseHead& base, const Mesh& fittedHead, const cv::Mat& headTexture,
                                   const PartColours& colours = {});

// One proxy on a fitted head, tinted with `colour` when it has a tint mask and `colour` is given. Only the triangles
// with a vertex at or above `keepAbove` (head-space y) are kept, and only the vertices they use.
AvatarPart placeProxyPart(const HeadProxy& proxy, const Mesh& fittedHead, const cv::Vec3d* colour = nullptr,
                          double keepAbove = -std::numeric_limits<double>::infinity());

// How much of `mesh`'s surface each texel of a `size` texture covers (mm² per texel, CV_32F), through its UVs. A
// triangle smaller than a texel gives its area to the texel under its centre.
cv::Mat surfacePerTexel(const Mesh& mesh, cv::Size size);

// The texture with its masked pixels recoloured: each keeps its own brightness relative to the masked pixels' mean
// (the iris' fibres, the strands' grain) and their mean becomes `bgr`; alpha and unmasked pixels are kept. With
// `weights` (surfacePerTexel), the mean is over the surface the texels cover and, in a BGRA texture, by how opaque
// they are: the colour is then what the part shows on average (the hair proxies' textures are dark at the strands'
// ends, which a bust cuts away, and light at the crown: their plain mean drew the hair far lighter than `bgr`).
cv::Mat tintTexture(const cv::Mat& texture, const cv::Mat& mask, const cv::Vec3d& bgr, const cv::Mat& weights = {});

// Moves a part up or down, each side of the face (x < 0, x > 0) on its own, so that its vertices within 4 mm (in x)
// of each point lie `below` millimetres under it on average, each keeping its height over `head`'s front surface (the
// surface seen from +z). The brows: the photo's own brows are on the texture where the fit put dlib's brow points,
// and a brow proxy where MakeHuman's artist drew it would make a second brow beside them. `points` are head-space
// (x, y). Sides with no point or no vertex near one stay.
void alignToPoints(AvatarPart& part, const Mesh& head, const std::vector<glm::dvec2>& points, double below);

// The mesh without the triangles that use any of `vertices`, its unused vertices dropped (UVs kept with them).
Mesh withoutVertices(const Mesh& mesh, const std::vector<std::uint32_t>& vertices);

}  // namespace avatarbooth
