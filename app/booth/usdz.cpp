// avatar.usdz: a USDA layer and its texture in a stored, 64-byte aligned zip (see usdz.h for the format's rules).
#include "booth/usdz.h"

#include "common/error.h"
#include "common/image_io.h"

#include <zlib.h>

#include <cctype>
#include <charconv>
#include <cstdint>
#include <limits>

namespace avatarbooth {
namespace {

constexpr double kMetresPerMm = 0.001;  // glTF's unit and this layer's (metersPerUnit = 1)
constexpr std::size_t kAlignment = 64;  // the USDZ specification's data alignment
constexpr std::uint16_t kPaddingFieldId = 0x1986;

// The shortest text that reads back as the same float.
void appendFloat(std::string& out, float v) {
    char buffer[32];
    const auto end = std::to_chars(buffer, buffer + sizeof buffer, v).ptr;
    out.append(buffer, end);
}

void appendTuple(std::string& out, std::initializer_list<float> values) {
    out += '(';
    bool first = true;
    for (const float v : values) {
        if (!first) out += ", ";
        appendFloat(out, v);
        first = false;
    }
    out += ')';
}

// A USDA array attribute, `type name = [items]` (+ metadata), on lines of about 100 characters.
template <typename Item>
void appendArray(std::string& out, const std::string& declaration, std::size_t count, Item item,
                 const std::string& metadata = "") {
    out += "        " + declaration + " = [";
    std::size_t lineStart = out.size();
    for (std::size_t i = 0; i < count; ++i) {
        if (i && out.size() - lineStart > 100) {
            out += ",\n            ";
            lineStart = out.size();
        } else if (i) {
            out += ", ";
        }
        item(out, i);
    }
    out += "]" + metadata + "\n";
}

void put16(std::string& out, std::uint32_t v) {
    out += static_cast<char>(v & 0xff);
    out += static_cast<char>((v >> 8) & 0xff);
}
void put32(std::string& out, std::uint32_t v) {
    put16(out, v & 0xffff);
    put16(out, v >> 16);
}

}  // namespace

namespace {

// One part's Mesh prim, bound to the material at `material`.
void appendMesh(std::string& u, const std::string& prim, const Mesh& mesh, bool textured, bool doubleSided,
                const std::string& material) {
    if (mesh.positions.empty() || mesh.triangles.empty())
        throw BoothError(ErrorKind::Internal, "", "cannot export an empty mesh");
    const std::size_t n = mesh.positions.size();
    glm::dvec3 lo, hi;
    mesh.bounds(lo, hi);
    const auto metres = [](double mm) { return static_cast<float>(mm * kMetresPerMm); };
    u += "    def Mesh \"" + prim + "\" (\n        prepend apiSchemas = [\"MaterialBindingAPI\"]\n    )\n    {\n";
    u += std::string("        uniform bool doubleSided = ") + (doubleSided ? "1" : "0") + "\n";
    u += "        float3[] extent = [";
    appendTuple(u, {metres(lo.x), metres(lo.y), metres(lo.z)});
    u += ", ";
    appendTuple(u, {metres(hi.x), metres(hi.y), metres(hi.z)});
    u += "]\n";
    appendArray(u, "int[] faceVertexCounts", mesh.triangles.size(), [](std::string& o, std::size_t) { o += '3'; });
    appendArray(u, "int[] faceVertexIndices", mesh.triangles.size(), [&](std::string& o, std::size_t i) {
        const auto& t = mesh.triangles[i];
        o += std::to_string(t.x) + ", " + std::to_string(t.y) + ", " + std::to_string(t.z);
    });
    u += "        rel material:binding = <" + material + ">\n";
    const std::vector<glm::dvec3> normals = mesh.vertexNormals();
    appendArray(u, "normal3f[] normals", n, [&](std::string& o, std::size_t i) {
        appendTuple(o, {static_cast<float>(normals[i].x), static_cast<float>(normals[i].y), static_cast<float>(normals[i].z)});
    }, " (\n            interpolation = \"vertex\"\n        )");
    appendArray(u, "point3f[] points", n, [&](std::string& o, std::size_t i) {
        const auto& p = mesh.positions[i];
        appendTuple(o, {metres(p.x), metres(p.y), metres(p.z)});
    });
    if (textured)
        appendArray(u, "texCoord2f[] primvars:st", n, [&](std::string& o, std::size_t i) {
            appendTuple(o, {static_cast<float>(mesh.uvs[i].x), static_cast<float>(1.0 - mesh.uvs[i].y)});
        }, " (\n            interpolation = \"vertex\"\n        )");
    u += "        uniform token subdivisionScheme = \"none\"\n    }\n\n";
}

// One UsdPreviewSurface material; its opacity from the texture's alpha for masked and blended parts.
void appendMaterial(std::string& u, const std::string& name, const std::string& textureFile, AlphaMode alpha,
                    double alphaCutoff) {
    const std::string material = "/avatar/Materials/" + name;
    const bool textured = !textureFile.empty();
    const bool withAlpha = textured && alpha != AlphaMode::Opaque;
    u += "        def Material \"" + name + "\"\n        {\n";
    u += "            token outputs:surface.connect = <" + material + "/surface.outputs:surface>\n\n";
    u += "            def Shader \"surface\"\n            {\n";
    u += "                uniform token info:id = \"UsdPreviewSurface\"\n";
    if (textured) u += "                color3f inputs:diffuseColor.connect = <" + material + "/texture.outputs:rgb>\n";
    else u += "                color3f inputs:diffuseColor = (0.8, 0.62, 0.52)\n";
    if (withAlpha) u += "                float inputs:opacity.connect = <" + material + "/texture.outputs:a>\n";
    if (withAlpha && alpha == AlphaMode::Mask) {
        u += "                float inputs:opacityThreshold = ";
        appendFloat(u, static_cast<float>(alphaCutoff));
        u += "\n";
    }
    u += "                float inputs:metallic = 0\n                float inputs:roughness = 0.8\n";
    u += "                token outputs:surface\n            }\n";
    if (textured) {
        u += "\n            def Shader \"st_reader\"\n            {\n";
        u += "                uniform token info:id = \"UsdPrimvarReader_float2\"\n";
        u += "                string inputs:varname = \"st\"\n                float2 outputs:result\n            }\n";
        u += "\n            def Shader \"texture\"\n            {\n";
        u += "                uniform token info:id = \"UsdUVTexture\"\n";
        u += "                asset inputs:file = @" + textureFile + "@\n";
        u += "                float2 inputs:st.connect = <" + material + "/st_reader.outputs:result>\n";
        u += "                token inputs:wrapS = \"clamp\"\n                token inputs:wrapT = \"clamp\"\n";
        u += "                float3 outputs:rgb\n";
        if (withAlpha) u += "                float outputs:a\n";
        u += "            }\n";
    }
    u += "        }\n";
}

// The layer of parts given as (prim name, material name, part, texture file or empty).
struct LayerPart {
    std::string prim, material;
    const AvatarPart* part;
    std::string textureFile;
};

std::string encodeLayer(const std::vector<LayerPart>& parts) {
    std::size_t size = 4096;
    for (const auto& p : parts) size += p.part->mesh.positions.size() * 120 + p.part->mesh.triangles.size() * 30;
    std::string u;
    u.reserve(size);
    u += "#usda 1.0\n(\n    defaultPrim = \"avatar\"\n    metersPerUnit = 1\n    upAxis = \"Y\"\n"
         "    doc = \"avatarbooth " AVATARBOOTH_VERSION "\"\n)\n\n";
    u += "def Xform \"avatar\" (\n    kind = \"component\"\n)\n{\n";
    for (const auto& p : parts)
        appendMesh(u, p.prim, p.part->mesh, !p.textureFile.empty() && p.part->mesh.uvs.size() == p.part->mesh.positions.size(),
                   p.part->alpha != AlphaMode::Opaque, "/avatar/Materials/" + p.material);
    u += "    def Scope \"Materials\"\n    {\n";
    for (std::size_t i = 0; i < parts.size(); ++i) {
        if (i) u += "\n";
        const auto& p = parts[i];
        const bool textured = !p.textureFile.empty() && p.part->mesh.uvs.size() == p.part->mesh.positions.size();
        appendMaterial(u, p.material, textured ? p.textureFile : "", p.part->alpha, p.part->alphaCutoff);
    }
    u += "    }\n}\n";
    return u;
}

// USD prim names are identifiers: letters, digits and underscores, not starting with a digit.
std::string primName(const std::string& name) {
    std::string out;
    for (const char c : name) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0]))) out = "part_" + out;
    return out;
}

}  // namespace

std::string encodeUsda(const Mesh& mesh, const std::string& textureFile) {
    AvatarPart part;
    part.mesh = mesh;
    return encodeLayer({{"head", "skin", &part, textureFile}});
}

std::string storeAlignedZip(const std::vector<std::pair<std::string, std::string_view>>& files) {
    // DOS date 1980-01-01 00:00: the archive's bytes depend on its contents only.
    constexpr std::uint32_t kDosTime = 0, kDosDate = (0u << 9) | (1u << 5) | 1u;
    std::string zip, central;
    for (const auto& [name, bytes] : files) {
        if (bytes.size() >= std::numeric_limits<std::uint32_t>::max() || name.empty() || name.size() > 0xffff)
            throw BoothError(ErrorKind::Internal, name, "cannot be stored in a plain (non-zip64) archive");
        const auto offset = static_cast<std::uint32_t>(zip.size());
        const auto crc = static_cast<std::uint32_t>(
            ::crc32(::crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(bytes.data()), static_cast<uInt>(bytes.size())));
        const auto size = static_cast<std::uint32_t>(bytes.size());
        // The data starts after the 30-byte header, the name and the extra field: pad the extra field to align it.
        std::size_t pad = (kAlignment - (zip.size() + 30 + name.size()) % kAlignment) % kAlignment;
        if (pad != 0 && pad < 4) pad += kAlignment;  // an extra field is at least its 4-byte id and length
        std::string extra;
        if (pad) {
            put16(extra, kPaddingFieldId);
            put16(extra, static_cast<std::uint32_t>(pad - 4));
            extra.append(pad - 4, '\0');
        }
        const auto common = [&](std::string& out) {
            put16(out, 20);  // version needed to extract: 2.0
            put16(out, 0);   // flags: no data descriptor, no encryption
            put16(out, 0);   // method: stored
            put16(out, kDosTime);
            put16(out, kDosDate);
            put32(out, crc);
            put32(out, size);  // compressed = uncompressed
            put32(out, size);
            put16(out, static_cast<std::uint32_t>(name.size()));
        };
        put32(zip, 0x04034b50);
        common(zip);
        put16(zip, static_cast<std::uint32_t>(extra.size()));
        zip += name;
        zip += extra;
        zip.append(bytes.data(), bytes.size());

        put32(central, 0x02014b50);
        put16(central, 20);  // made by: MS-DOS/FAT attributes, version 2.0
        common(central);
        put16(central, 0);  // no extra field here: only the local data needs aligning
        put16(central, 0);  // comment
        put16(central, 0);  // disk
        put16(central, 0);  // internal attributes
        put32(central, 0);  // external attributes
        put32(central, offset);
        central += name;
    }
    const auto centralOffset = static_cast<std::uint32_t>(zip.size());
    zip += central;
    put32(zip, 0x06054b50);
    put16(zip, 0);
    put16(zip, 0);
    put16(zip, static_cast<std::uint32_t>(files.size()));
    put16(zip, static_cast<std::uint32_t>(files.size()));
    put32(zip, static_cast<std::uint32_t>(central.size()));
    put32(zip, centralOffset);
    put16(zip, 0);
    return zip;
}

std::string encodeUsdz(const Mesh& mesh, const cv::Mat& texture) {
    AvatarPart part;
    part.name = "head";
    part.mesh = mesh;
    part.texture = texture;
    return encodeUsdz(std::vector<AvatarPart>{std::move(part)});
}

std::string encodeUsdz(const std::vector<AvatarPart>& parts) {
    if (parts.empty()) throw BoothError(ErrorKind::Internal, "", "cannot export an avatar without parts");
    // The first part is the head, its material "skin" and its texture "texture.jpg" (as the single-mesh layer);
    // every other part is named after itself, its texture a PNG where its alpha counts.
    std::vector<LayerPart> layer;
    std::vector<std::string> images;
    images.reserve(parts.size());
    for (std::size_t i = 0; i < parts.size(); ++i) {
        const AvatarPart& part = parts[i];
        const bool textured = !part.texture.empty() && part.mesh.uvs.size() == part.mesh.positions.size();
        const bool withAlpha = part.alpha != AlphaMode::Opaque && part.texture.channels() == 4;
        const std::string name = i == 0 ? "head" : primName(part.name);
        std::string file;
        if (textured) {
            file = i == 0 ? "texture.jpg" : name + (withAlpha ? ".png" : ".jpg");
            // The glb's texture quality (fit/export/glb.cpp), so both AR files look the same.
            images.push_back(withAlpha ? encodeImage(part.texture, ".png") : encodeImage(part.texture, ".jpg", 92));
        } else {
            images.emplace_back();
        }
        layer.push_back({name, i == 0 ? "skin" : name, &part, file});
    }
    const std::string usda = encodeLayer(layer);
    std::vector<std::pair<std::string, std::string_view>> files{{"avatar.usda", usda}};
    for (std::size_t i = 0; i < layer.size(); ++i)
        if (!layer[i].textureFile.empty()) files.emplace_back(layer[i].textureFile, images[i]);
    return storeAlignedZip(files);
}

}  // namespace avatarbooth
