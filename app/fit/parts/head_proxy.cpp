// Head proxies: placing them by their binding, and their files beside the base head.
#include "fit/parts/head_proxy.h"

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/file_bytes.h"
#include "common/image_io.h"

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include <fstream>

namespace avatarbooth {
namespace {

namespace fs = std::filesystem;

constexpr const char* kFormat = "avatarbooth-head-proxy/1";

AlphaMode alphaModeOf(const std::string& text, const std::string& where) {
    for (const AlphaMode m : {AlphaMode::Opaque, AlphaMode::Mask, AlphaMode::Blend})
        if (text == toString(m)) return m;
    throw BoothError(ErrorKind::BadConfig, where, "field 'alpha' must be OPAQUE, MASK or BLEND (is '" + text + "')");
}

}  // namespace

const char* toString(AlphaMode mode) {
    switch (mode) {
        case AlphaMode::Opaque: return "OPAQUE";
        case AlphaMode::Mask: return "MASK";
        case AlphaMode::Blend: return "BLEND";
    }
    return "OPAQUE";
}

std::vector<const AvatarPart*> drawOrder(const std::vector<AvatarPart>& parts) {
    std::vector<const AvatarPart*> out;
    for (const AlphaMode mode : {AlphaMode::Opaque, AlphaMode::Mask, AlphaMode::Blend})
        for (const AvatarPart& p : parts)
            if (p.alpha == mode) out.push_back(&p);
    return out;
}

std::vector<glm::dvec3> placeProxy(const ProxyBinding& b, const std::vector<glm::dvec3>& head) {
    if (b.weights.size() != b.vertices.size() || b.offsets.size() != b.vertices.size())
        throw BoothError(ErrorKind::Internal, "proxy binding",
                         "has " + std::to_string(b.vertices.size()) + " vertex triples, " + std::to_string(b.weights.size()) +
                             " weights and " + std::to_string(b.offsets.size()) + " offsets");
    std::vector<glm::dvec3> out(b.vertices.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        glm::dvec3 p = b.offsets[i];
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = b.vertices[i][static_cast<std::size_t>(k)];
            if (v >= head.size())
                throw BoothError(ErrorKind::Internal, "proxy binding",
                                 "refers to vertex " + std::to_string(v) + " of a head with " + std::to_string(head.size()));
            p += b.weights[i][k] * head[v];
        }
        out[i] = p;
    }
    return out;
}

std::string saveHeadProxy(const HeadProxy& p, const fs::path& dir) {
    nlohmann::json j;
    j["format"] = kFormat;
    j["name"] = p.name;
    j["source"] = p.source;
    j["alpha"] = toString(p.alpha);
    j["alpha_cutoff"] = p.alphaCutoff;
    j["units"] = "offsets in millimetres; uvs with (0, 0) the texture's top-left corner";
    auto& vertices = j["binding"]["vertices"] = nlohmann::json::array();
    auto& weights = j["binding"]["weights"] = nlohmann::json::array();
    auto& offsets = j["binding"]["offsets"] = nlohmann::json::array();
    for (std::size_t i = 0; i < p.binding.vertices.size(); ++i) {
        vertices.push_back(p.binding.vertices[i]);
        weights.push_back({p.binding.weights[i].x, p.binding.weights[i].y, p.binding.weights[i].z});
        offsets.push_back({p.binding.offsets[i].x, p.binding.offsets[i].y, p.binding.offsets[i].z});
    }
    auto& uvs = j["uvs"] = nlohmann::json::array();
    for (const auto& uv : p.mesh.uvs) uvs.push_back({uv.x, uv.y});
    auto& triangles = j["triangles"] = nlohmann::json::array();
    for (const auto& t : p.mesh.triangles) triangles.push_back({t.x, t.y, t.z});
    j["replaces"] = p.replaces;
    // Named by the part and, when several proxies make the same part (the hair styles), by the source's folder too.
    const std::string leaf = fs::path(p.source).filename().string();
    const std::string stem = leaf.empty() || leaf == p.name ? p.name : p.name + "_" + leaf;
    j["texture"] = stem + ".png";
    writeFileAtomically(dir / (stem + ".png"), encodeImage(p.texture, ".png"));
    if (!p.tintMask.empty()) {
        j["tint_mask"] = stem + ".tint.png";
        writeFileAtomically(dir / (stem + ".tint.png"), encodeImage(p.tintMask, ".png"));
    }
    const std::string file = stem + ".json";
    writeFileAtomically(dir / file, j.dump() + "\n");
    return file;
}

namespace {

PhotoLimits textureLimits() {
    PhotoLimits limits;
    limits.minSide = 1;  // a texture may be small; the photos' lower limit is for faces
    return limits;
}
const PhotoLimits kTextureLimits = textureLimits();

// The texture as the alpha mode wants it, the tint mask as one channel, and their sizes checked.
void finishPixels(HeadProxy& p, const std::string& where) {
    if (p.alpha == AlphaMode::Opaque) cv::cvtColor(p.texture, p.texture, cv::COLOR_BGRA2BGR);
    if (!p.tintMask.empty()) {
        cv::Mat one;
        cv::extractChannel(p.tintMask, one, 0);
        p.tintMask = one;
        if (p.tintMask.size() != p.texture.size())
            throw BoothError(ErrorKind::BadConfig, where, "its tint mask and texture differ in size");
    }
}

// Bytes loadHeadProxy read and checked once, decoded again when the proxy is placed.
cv::Mat decodeHeld(const std::string& bytes, bool alpha, const std::string& where) {
    try {
        return decodeCheckedImage(bytes, where, kTextureLimits, alpha);
    } catch (const BoothError& e) {
        throw BoothError(ErrorKind::BadConfig, where, std::string("its texture does not decode: ") + e.what());
    }
}

}  // namespace

std::pair<cv::Mat, cv::Mat> proxyPixels(const HeadProxy& proxy) {
    if (!proxy.texture.empty() || proxy.encodedTexture.empty()) return {proxy.texture, proxy.tintMask};
    HeadProxy p;
    p.alpha = proxy.alpha;
    const std::string where = "head proxy " + proxy.source;
    p.texture = decodeHeld(proxy.encodedTexture, true, where);
    if (!proxy.encodedTintMask.empty()) p.tintMask = decodeHeld(proxy.encodedTintMask, false, where);
    finishPixels(p, where);
    return {p.texture, p.tintMask};
}

void holdEncoded(HeadProxy& proxy) {
    if (proxy.encodedTexture.empty() || (!proxy.tintMask.empty() && proxy.encodedTintMask.empty())) return;
    proxy.texture.release();
    proxy.tintMask.release();
}

HeadProxy loadHeadProxy(const fs::path& file, const std::vector<glm::dvec3>& head) {
    const std::string where = file.string();
    std::ifstream in(file);
    if (!in) throw BoothError(ErrorKind::BadConfig, where, "cannot be opened");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(in);
    } catch (const nlohmann::json::parse_error& e) {
        throw BoothError(ErrorKind::BadConfig, where, std::string("is not valid JSON: ") + e.what());
    }
    HeadProxy p;
    const auto field = [&](const char* key) -> const nlohmann::json& {
        if (!j.contains(key)) throw BoothError(ErrorKind::BadConfig, where, std::string("missing field '") + key + "'");
        return j[key];
    };
    try {
        if (field("format") != kFormat)
            throw BoothError(ErrorKind::BadConfig, where, std::string("field 'format' must be ") + kFormat);
        p.name = field("name").get<std::string>();
        p.source = j.value("source", "");
        p.alpha = alphaModeOf(field("alpha").get<std::string>(), where);
        p.alphaCutoff = j.value("alpha_cutoff", 0.5);
        const auto& b = field("binding");
        const auto& vertices = b.at("vertices");
        const auto& weights = b.at("weights");
        const auto& offsets = b.at("offsets");
        if (weights.size() != vertices.size() || offsets.size() != vertices.size())
            throw BoothError(ErrorKind::BadConfig, where, "field 'binding' has lists of different lengths");
        for (std::size_t i = 0; i < vertices.size(); ++i) {
            std::array<std::uint32_t, 3> v{};
            for (std::size_t k = 0; k < 3; ++k) {
                v[k] = vertices.at(i).at(k).get<std::uint32_t>();
                if (v[k] >= head.size())
                    throw BoothError(ErrorKind::BadConfig, where, "field 'binding.vertices' refers to vertex " + std::to_string(v[k]) +
                                                                      " of a base head with " + std::to_string(head.size()));
            }
            p.binding.vertices.push_back(v);
            p.binding.weights.emplace_back(weights.at(i).at(0).get<double>(), weights.at(i).at(1).get<double>(), weights.at(i).at(2).get<double>());
            p.binding.offsets.emplace_back(offsets.at(i).at(0).get<double>(), offsets.at(i).at(1).get<double>(), offsets.at(i).at(2).get<double>());
        }
        for (const auto& uv : field("uvs")) p.mesh.uvs.emplace_back(uv.at(0).get<double>(), uv.at(1).get<double>());
        if (p.mesh.uvs.size() != vertices.size())
            throw BoothError(ErrorKind::BadConfig, where, "field 'uvs' has " + std::to_string(p.mesh.uvs.size()) + " for " +
                                                              std::to_string(vertices.size()) + " vertices");
        for (const auto& t : field("triangles")) {
            const glm::uvec3 tri(t.at(0).get<std::uint32_t>(), t.at(1).get<std::uint32_t>(), t.at(2).get<std::uint32_t>());
            if (tri.x >= vertices.size() || tri.y >= vertices.size() || tri.z >= vertices.size())
                throw BoothError(ErrorKind::BadConfig, where, "field 'triangles' refers past the " + std::to_string(vertices.size()) + " vertices");
            p.mesh.triangles.push_back(tri);
        }
        for (const auto& v : j.value("replaces", nlohmann::json::array())) {
            if (v.get<std::uint64_t>() >= head.size())
                throw BoothError(ErrorKind::BadConfig, where, "field 'replaces' refers past the base head's vertices");
            p.replaces.push_back(v.get<std::uint32_t>());
        }
        // Each file read once and checked; its bytes are kept too, for holdEncoded.
        const fs::path textureFile = file.parent_path() / field("texture").get<std::string>();
        p.encodedTexture = readFileBytes(textureFile);
        p.texture = decodeCheckedImage(p.encodedTexture, textureFile.string(), kTextureLimits, true);
        if (j.contains("tint_mask")) {
            const fs::path maskFile = file.parent_path() / j["tint_mask"].get<std::string>();
            p.encodedTintMask = readFileBytes(maskFile);
            p.tintMask = decodeCheckedImage(p.encodedTintMask, maskFile.string(), kTextureLimits, false);
        }
        finishPixels(p, where);
    } catch (const nlohmann::json::exception& e) {
        throw BoothError(ErrorKind::BadConfig, where, std::string("not a head proxy as expected: ") + e.what());
    }
    p.mesh.positions = placeProxy(p.binding, head);
    return p;
}

}  // namespace avatarbooth
