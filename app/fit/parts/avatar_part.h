// The avatar as the booth shows and exports it: a list of parts, each a mesh with its own texture and the way its
// texture's alpha is used. The head comes first (opaque, the photos' texture); after it the parts placed on the
// fitted head through their bindings (head_proxy.h): eyes, eyebrows, eyelashes, and hair and beard.
//
// To add a part: give the base head a HeadProxy for it (makehuman_import.cpp binds MakeHuman's proxies; any mesh
// bound to the base head's vertices will do), and placeParts (avatar_parts.h) places it on every fitted head; the
// renderer, the glb and the usdz take every part in the list without knowing its name. A part whose colour comes
// from the photo gets a tint mask (HeadProxy::tintMask) and a colour in PartColours.
#pragma once

#include "fit/head/mesh.h"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace avatarbooth {

// glTF's alpha modes: Opaque ignores the texture's alpha; Mask keeps a fragment where alpha >= alphaCutoff and
// drops the rest (lashes: sharp, no sorting); Blend mixes it over what lies behind (brows: soft strands).
enum class AlphaMode { Opaque, Mask, Blend };

const char* toString(AlphaMode mode);  // "OPAQUE", "MASK", "BLEND" (glTF's spelling)

struct AvatarPart {
    std::string name;    // "head", "eyes", "eyebrows", "eyelashes", "hair", "beard", ...: names the glTF node
    Mesh mesh;           // head space, millimetres (mesh.h), with UVs
    cv::Mat texture;     // 8-bit BGR, or BGRA when alpha is not Opaque; empty: untextured
    AlphaMode alpha = AlphaMode::Opaque;
    double alphaCutoff = 0.5;  // Mask only
};

// The order they are drawn in: opaque parts, then masked, then blended (each group in list order).
std::vector<const AvatarPart*> drawOrder(const std::vector<AvatarPart>& parts);

}  // namespace avatarbooth
