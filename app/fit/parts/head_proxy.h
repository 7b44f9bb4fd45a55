// A mesh bound to the base head (MakeHuman's proxies: eyes, eyebrows, eyelashes, hair, beard): each of its vertices
// sits at a weighted sum of three base-head vertices plus an offset, MakeHuman's own binding (its .mhclo files;
// makehuman_import.cpp reads them). The fit keeps the base head's topology, so the same sum over the fitted head's
// vertices carries the proxy along with every modifier and the warp.
//
// To add a proxy: bind it (three head vertices, weights summing to 1 and an offset per vertex), give it triangles,
// UVs, a texture and an alpha mode, and append it to BaseHead::proxies; saveHeadProxy/loadHeadProxy keep it beside
// the base head (the feature file lists them) and placeParts puts it on every fitted head.
#pragma once

#include "fit/head/mesh.h"
#include "fit/parts/avatar_part.h"

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace avatarbooth {

// Proxy vertex i = sum_k weights[i][k] * head[vertices[i][k]] + offsets[i] (millimetres).
struct ProxyBinding {
    std::vector<std::array<std::uint32_t, 3>> vertices;  // base-head vertex indices
    std::vector<glm::dvec3> weights;
    std::vector<glm::dvec3> offsets;
};

// The proxy's vertices on a head of the base head's topology. Throws BoothError(Internal) when a binding refers past
// the head's vertices or the three lists differ in length.
std::vector<glm::dvec3> placeProxy(const ProxyBinding& binding, const std::vector<glm::dvec3>& head);

struct HeadProxy {
    std::string name;     // the part it becomes (AvatarPart::name)
    std::string source;   // where it came from, e.g. MakeHuman's "proxies/eyes/HighPolyEyes"
    Mesh mesh;            // triangles and UVs; positions as placed on the base head
    ProxyBinding binding;
    cv::Mat texture;      // BGR or BGRA
    AlphaMode alpha = AlphaMode::Opaque;
    double alphaCutoff = 0.5;
    // CV_8U on the texture's pixels, 255 where the visitor's colour goes (the iris; a brow's strands); empty: the
    // texture is shown as it is.
    cv::Mat tintMask;
    // Base-head vertices whose triangles this part replaces in the head part (the eyes: hm08's own eyeballs).
    std::vector<std::uint32_t> replaces;
    // A proxy that is one of several alternatives for its part (the hair styles, of which a fit places one) may hold
    // its texture and tint mask encoded instead (their files' bytes, texture and tintMask then empty): the four
    // styles' pixels were 5 MB of the kiosk's memory from start-up on. proxyPixels() decodes them.
    std::string encodedTexture, encodedTintMask;
};

// The proxy's texture and tint mask as pixels: its own, or those it holds encoded, decoded (as loadHeadProxy reads
// them). Throws BoothError(BadConfig) naming the proxy when they no longer decode.
std::pair<cv::Mat, cv::Mat> proxyPixels(const HeadProxy& proxy);
// Lets go of the proxy's pixels, keeping their encoded bytes (which loadHeadProxy keeps for this).
void holdEncoded(HeadProxy& proxy);

// Writes NAME.json (binding, triangles, UVs, alpha, replaced vertices), NAME.png (texture) and, when there is one,
// NAME.tint.png into `dir`, NAME being the part's name and the source's folder (eyes_HighPolyEyes; several
// proxies make the same part: the hair styles); returns NAME.json's file name.
std::string saveHeadProxy(const HeadProxy& proxy, const std::filesystem::path& dir);
// Reads what saveHeadProxy wrote and places it on `head` (the base head's positions; the binding must refer to them).
// Throws BoothError(BadConfig) naming the file and the field.
HeadProxy loadHeadProxy(const std::filesystem::path& json, const std::vector<glm::dvec3>& head);

}  // namespace avatarbooth
