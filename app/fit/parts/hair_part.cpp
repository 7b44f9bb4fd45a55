// The hair part (hair_part.h).
#include "fit/parts/hair_part.h"

#include "common/error.h"
#include "common/landmark_names.h"
#include "fit/parts/avatar_parts.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace avatarbooth {

void keepFaceClear(Mesh& hair, const BaseHead& base, const Mesh& fittedHead, const FaceClearance& clearance) {
    const auto at = [&](int k) -> const glm::dvec3& {
        const auto it = base.frontFeatures.find(landmarkName(k));
        if (it == base.frontFeatures.end() || it->second >= fittedHead.positions.size())
            throw BoothError(ErrorKind::Internal, "hair part", "the base head has no feature vertex " + landmarkName(k));
        return fittedHead.positions[it->second];
    };
    double browY = at(17).y;
    for (int k = 18; k <= 26; ++k) browY = std::min(browY, at(k).y);
    const double sideZ = 0.5 * (at(0).z + at(16).z);
    for (glm::dvec3& p : hair.positions) {
        if (p.z <= sideZ) continue;
        // 0 from `ramp` over the brows up, 1 from the brows down, smooth between (no crease in a strand).
        const double t = std::clamp((browY + clearance.ramp - p.y) / clearance.ramp, 0.0, 1.0);
        // Ahead of the plane, depth is compressed into `depth` millimetres, keeping its order: the strands stay
        // layered as they were, not collapsed onto one flat wall.
        const double ahead = p.z - sideZ;
        const double kept = clearance.depth * (1.0 - std::exp(-ahead / clearance.depth));
        p.z -= t * t * (3.0 - 2.0 * t) * (ahead - kept);
    }
}

const char* hairProxyName(HairStyle style) {
    switch (style) {
        case HairStyle::None: return nullptr;
        case HairStyle::Short: return "short04";
        case HairStyle::Bob: return "bob02";
        case HairStyle::Long: return "long01";
        case HairStyle::Ponytail: return "ponytail01";
    }
    return nullptr;
}

bool isHairStyleProxy(const HeadProxy& proxy) { return proxy.name == "hair"; }

const HeadProxy* findHairProxy(const BaseHead& base, std::string_view proxyName) {
    const std::string source = "proxies/hair/" + std::string(proxyName);
    for (const HeadProxy& p : base.proxies)
        if (isHairStyleProxy(p) && p.source == source) return &p;
    return nullptr;
}

std::optional<AvatarPart> placeHairPart(const BaseHead& base, const Mesh& fittedHead, const HairEstimate& hair) {
    const char* name = hairProxyName(hair.style);
    return name == nullptr ? std::nullopt : placeHairPart(base, fittedHead, name, hair.colour);
}

std::optional<AvatarPart> placeHairPart(const BaseHead& base, const Mesh& fittedHead, std::string_view proxyName,
                                        const cv::Vec3d& colour) {
    const HeadProxy* proxy = findHairProxy(base, proxyName);
    if (proxy == nullptr) return std::nullopt;
    std::optional<AvatarPart> part = placeProxyPart(*proxy, fittedHead, &colour);
    // The avatar is a bust cut under the chin: long hair ends where the neck does, not in the air at waist height
    // (which also made every preview frame a head a third of its size).
    if (part) {
        glm::dvec3 lo, hi;
        fittedHead.bounds(lo, hi);
        // Only the vertices the kept triangles use stay (the previews frame a part by its vertices).
        Mesh& m = part->mesh;
        Mesh cut;
        std::vector<std::uint32_t> newIndex(m.positions.size(), UINT32_MAX);
        const auto keep = [&](std::uint32_t v) {
            if (newIndex[v] == UINT32_MAX) {
                newIndex[v] = static_cast<std::uint32_t>(cut.positions.size());
                cut.positions.push_back(m.positions[v]);
                if (!m.uvs.empty()) cut.uvs.push_back(m.uvs[v]);
            }
            return newIndex[v];
        };
        for (const auto& t : m.triangles)
            if (m.positions[t.x].y >= lo.y || m.positions[t.y].y >= lo.y || m.positions[t.z].y >= lo.y)
                cut.triangles.emplace_back(keep(t.x), keep(t.y), keep(t.z));
        m = std::move(cut);
    }
    return part;
}

}  // namespace avatarbooth
