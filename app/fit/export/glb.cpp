// glb writing and reading through tinygltf (Debian's libtinygltf: the implementation lives in the library).
#include "fit/export/glb.h"

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/image_io.h"

#include <opencv2/imgproc.hpp>
#include <tiny_gltf.h>

#include <cstring>
#include <sstream>

namespace avatarbooth {
namespace {

constexpr double kMetresPerMm = 0.001;

// Appends raw bytes to the buffer (4-byte aligned, as glTF requires for accessors) and returns a view on them.
int addBufferView(tinygltf::Model& model, const void* data, std::size_t size, int target) {
    auto& buffer = model.buffers[0].data;
    while (buffer.size() % 4 != 0) buffer.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.size();
    view.byteLength = size;
    view.target = target;
    const auto* bytes = static_cast<const unsigned char*>(data);
    buffer.insert(buffer.end(), bytes, bytes + size);
    model.bufferViews.push_back(view);
    return static_cast<int>(model.bufferViews.size() - 1);
}

int addAccessor(tinygltf::Model& model, int view, int componentType, int type, std::size_t count,
                std::vector<double> minValues = {}, std::vector<double> maxValues = {}) {
    tinygltf::Accessor accessor;
    accessor.bufferView = view;
    accessor.componentType = componentType;
    accessor.type = type;
    accessor.count = count;
    accessor.minValues = std::move(minValues);
    accessor.maxValues = std::move(maxValues);
    model.accessors.push_back(accessor);
    return static_cast<int>(model.accessors.size() - 1);
}

}  // namespace

namespace {

// One part as one glTF mesh (one primitive), material, texture and node.
void addPart(tinygltf::Model& model, const AvatarPart& part) {
    const Mesh& mesh = part.mesh;
    if (mesh.positions.empty() || mesh.triangles.empty())
        throw BoothError(ErrorKind::Internal, "", "cannot export an empty mesh (part '" + part.name + "')");
    const std::size_t n = mesh.positions.size();
    std::vector<float> positions, normals, uvs;
    positions.reserve(3 * n);
    std::vector<double> lo(3, 1e30), hi(3, -1e30);
    for (const auto& p : mesh.positions) {
        for (int c = 0; c < 3; ++c) {
            const float v = static_cast<float>(p[c] * kMetresPerMm);
            positions.push_back(v);
            lo[static_cast<std::size_t>(c)] = std::min(lo[static_cast<std::size_t>(c)], static_cast<double>(v));
            hi[static_cast<std::size_t>(c)] = std::max(hi[static_cast<std::size_t>(c)], static_cast<double>(v));
        }
    }
    for (const auto& nrm : mesh.vertexNormals()) {
        // A vertex of no area (an unused one, a degenerate fan) gets some unit normal: glTF asks for unit length.
        const glm::dvec3 unit = glm::length(nrm) > 0.5 ? nrm : glm::dvec3(0.0, 0.0, 1.0);
        for (int c = 0; c < 3; ++c) normals.push_back(static_cast<float>(unit[c]));
    }
    for (const auto& uv : mesh.uvs) {
        uvs.push_back(static_cast<float>(uv.x));
        uvs.push_back(static_cast<float>(uv.y));
    }
    std::vector<std::uint32_t> indices;
    indices.reserve(3 * mesh.triangles.size());
    for (const auto& t : mesh.triangles) indices.insert(indices.end(), {t.x, t.y, t.z});

    tinygltf::Primitive primitive;
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    primitive.attributes["POSITION"] =
        addAccessor(model, addBufferView(model, positions.data(), positions.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER),
                    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n, lo, hi);
    primitive.attributes["NORMAL"] =
        addAccessor(model, addBufferView(model, normals.data(), normals.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER),
                    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n);
    if (mesh.uvs.size() == n)
        primitive.attributes["TEXCOORD_0"] =
            addAccessor(model, addBufferView(model, uvs.data(), uvs.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER),
                        TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, n);
    primitive.indices = addAccessor(
        model, addBufferView(model, indices.data(), indices.size() * sizeof(std::uint32_t), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
        TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, indices.size());

    tinygltf::Material material;
    material.name = part.name + (part.name == "head" || model.materials.empty() ? "-skin" : "-material");
    material.pbrMetallicRoughness.metallicFactor = 0.0;
    material.pbrMetallicRoughness.roughnessFactor = 0.8;
    material.alphaMode = toString(part.alpha);
    if (part.alpha == AlphaMode::Mask) material.alphaCutoff = part.alphaCutoff;
    // Brows and lashes are cards seen from both sides.
    material.doubleSided = part.alpha != AlphaMode::Opaque;
    if (!part.texture.empty() && mesh.uvs.size() == n) {
        // JPEG for the opaque textures (the photos' head: small), PNG where the alpha matters.
        const bool withAlpha = part.alpha != AlphaMode::Opaque && part.texture.channels() == 4;
        const std::string bytes = withAlpha ? encodeImage(part.texture, ".png") : encodeImage(part.texture, ".jpg", 92);
        tinygltf::Image image;
        image.name = part.name + "-texture";
        image.mimeType = withAlpha ? "image/png" : "image/jpeg";
        image.bufferView = addBufferView(model, bytes.data(), bytes.size(), 0);
        model.images.push_back(image);
        if (model.samplers.empty()) {
            tinygltf::Sampler sampler;
            sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
            sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
            sampler.wrapS = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
            sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
            model.samplers.push_back(sampler);
        }
        tinygltf::Texture tex;
        tex.sampler = 0;
        tex.source = static_cast<int>(model.images.size() - 1);
        model.textures.push_back(tex);
        material.pbrMetallicRoughness.baseColorTexture.index = static_cast<int>(model.textures.size() - 1);
    } else {
        material.pbrMetallicRoughness.baseColorFactor = {0.80, 0.62, 0.52, 1.0};
    }
    model.materials.push_back(material);
    primitive.material = static_cast<int>(model.materials.size() - 1);

    tinygltf::Mesh gltfMesh;
    gltfMesh.name = part.name;
    gltfMesh.primitives.push_back(primitive);
    model.meshes.push_back(gltfMesh);
    tinygltf::Node node;
    node.name = part.name;
    node.mesh = static_cast<int>(model.meshes.size() - 1);
    model.nodes.push_back(node);
}

}  // namespace

std::string encodeGlb(const std::vector<AvatarPart>& parts) {
    if (parts.empty()) throw BoothError(ErrorKind::Internal, "", "cannot export an avatar without parts");
    tinygltf::Model model;
    model.asset.version = "2.0";
    model.asset.generator = std::string("avatarbooth ") + AVATARBOOTH_VERSION;
    model.buffers.resize(1);
    tinygltf::Scene scene;
    for (const AvatarPart& part : parts) {
        addPart(model, part);
        scene.nodes.push_back(static_cast<int>(model.nodes.size() - 1));
    }
    model.scenes.push_back(scene);
    model.defaultScene = 0;
    model.buffers[0].data.resize((model.buffers[0].data.size() + 3) / 4 * 4, 0);

    std::ostringstream out;
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&model, out, false, true))
        throw BoothError(ErrorKind::Internal, "", "tinygltf could not write the glb");
    return out.str();
}

std::string encodeGlb(const Mesh& mesh, const cv::Mat& texture, const std::string& name) {
    AvatarPart part;
    part.name = name;
    part.mesh = mesh;
    part.texture = texture;
    return encodeGlb(std::vector<AvatarPart>{std::move(part)});
}

void writeGlb(const std::filesystem::path& path, const Mesh& mesh, const cv::Mat& texture, const std::string& name) {
    writeFileAtomically(path, encodeGlb(mesh, texture, name));
}

namespace {

tinygltf::Model loadModel(const std::filesystem::path& path) {
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    if (!std::filesystem::is_regular_file(path)) throw BoothError(ErrorKind::BadConfig, path.string(), "file not found");
    if (!loader.LoadBinaryFromFile(&model, &err, &warn, path.string()))
        throw BoothError(ErrorKind::BadConfig, path.string(), "is not a valid glb: " + err);
    return model;
}

template <typename T>
const T* accessorData(const tinygltf::Model& model, int accessorIndex, int expectType, int expectComponent,
                      const std::string& where, const char* what, std::size_t& count) {
    if (accessorIndex < 0 || accessorIndex >= static_cast<int>(model.accessors.size()))
        throw BoothError(ErrorKind::BadConfig, where, std::string("has no ") + what);
    const auto& accessor = model.accessors[static_cast<std::size_t>(accessorIndex)];
    if (accessor.type != expectType || accessor.componentType != expectComponent || accessor.bufferView < 0)
        throw BoothError(ErrorKind::BadConfig, where, std::string(what) + " has an unsupported layout");
    const auto& view = model.bufferViews[static_cast<std::size_t>(accessor.bufferView)];
    if (view.byteStride != 0 && view.byteStride != sizeof(T) * static_cast<std::size_t>(tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(expectType))))
        throw BoothError(ErrorKind::BadConfig, where, std::string(what) + " is interleaved (not supported)");
    const auto& buffer = model.buffers[static_cast<std::size_t>(view.buffer)];
    const std::size_t offset = view.byteOffset + accessor.byteOffset;
    const std::size_t bytes = accessor.count * sizeof(T) * static_cast<std::size_t>(tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(expectType)));
    if (offset + bytes > buffer.data.size()) throw BoothError(ErrorKind::BadConfig, where, std::string(what) + " runs past its buffer");
    count = accessor.count;
    return reinterpret_cast<const T*>(buffer.data.data() + offset);
}

}  // namespace

Mesh readGlbMesh(const std::filesystem::path& path) {
    const std::string where = path.string();
    const tinygltf::Model model = loadModel(path);
    if (model.meshes.empty() || model.meshes[0].primitives.empty())
        throw BoothError(ErrorKind::BadConfig, where, "holds no mesh");
    const auto& primitive = model.meshes[0].primitives[0];
    if (primitive.mode != TINYGLTF_MODE_TRIANGLES && primitive.mode != -1)
        throw BoothError(ErrorKind::BadConfig, where, "first primitive is not made of triangles");
    Mesh mesh;
    std::size_t count = 0;
    const auto pos = primitive.attributes.find("POSITION");
    const float* p = accessorData<float>(model, pos == primitive.attributes.end() ? -1 : pos->second, TINYGLTF_TYPE_VEC3,
                                         TINYGLTF_COMPONENT_TYPE_FLOAT, where, "POSITION", count);
    for (std::size_t i = 0; i < count; ++i)
        mesh.positions.emplace_back(p[3 * i] / kMetresPerMm, p[3 * i + 1] / kMetresPerMm, p[3 * i + 2] / kMetresPerMm);
    const auto uv = primitive.attributes.find("TEXCOORD_0");
    if (uv != primitive.attributes.end()) {
        std::size_t uvCount = 0;
        const float* t = accessorData<float>(model, uv->second, TINYGLTF_TYPE_VEC2, TINYGLTF_COMPONENT_TYPE_FLOAT, where,
                                             "TEXCOORD_0", uvCount);
        if (uvCount != count) throw BoothError(ErrorKind::BadConfig, where, "TEXCOORD_0 and POSITION differ in length");
        for (std::size_t i = 0; i < uvCount; ++i) mesh.uvs.emplace_back(t[2 * i], t[2 * i + 1]);
    } else {
        throw BoothError(ErrorKind::BadConfig, where, "has no texture coordinates (TEXCOORD_0): a base head needs UVs");
    }
    std::size_t indexCount = 0;
    if (primitive.indices < 0) throw BoothError(ErrorKind::BadConfig, where, "has no index buffer");
    const int componentType = model.accessors[static_cast<std::size_t>(primitive.indices)].componentType;
    std::vector<std::uint32_t> indices;
    if (componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
        const auto* idx = accessorData<std::uint32_t>(model, primitive.indices, TINYGLTF_TYPE_SCALAR, componentType, where, "indices", indexCount);
        indices.assign(idx, idx + indexCount);
    } else if (componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
        const auto* idx = accessorData<std::uint16_t>(model, primitive.indices, TINYGLTF_TYPE_SCALAR, componentType, where, "indices", indexCount);
        indices.assign(idx, idx + indexCount);
    } else {
        throw BoothError(ErrorKind::BadConfig, where, "indices have an unsupported type");
    }
    if (indices.size() % 3 != 0) throw BoothError(ErrorKind::BadConfig, where, "index count is not a multiple of 3");
    for (std::size_t i = 0; i < indices.size(); i += 3) {
        if (indices[i] >= count || indices[i + 1] >= count || indices[i + 2] >= count)
            throw BoothError(ErrorKind::BadConfig, where, "an index points past the vertices");
        mesh.triangles.emplace_back(indices[i], indices[i + 1], indices[i + 2]);
    }
    return mesh;
}

cv::Mat readGlbTexture(const std::filesystem::path& path) {
    const tinygltf::Model model = loadModel(path);
    if (model.materials.empty()) return {};
    const int texIndex = model.materials[0].pbrMetallicRoughness.baseColorTexture.index;
    if (texIndex < 0) return {};
    const int source = model.textures[static_cast<std::size_t>(texIndex)].source;
    const auto& image = model.images[static_cast<std::size_t>(source)];
    // tinygltf decodes embedded images to RGBA(8) pixels.
    if (image.image.empty() || image.bits != 8) return {};
    cv::Mat rgba(image.height, image.width, image.component == 4 ? CV_8UC4 : CV_8UC3,
                 const_cast<unsigned char*>(image.image.data()));
    cv::Mat bgr;
    cv::cvtColor(rgba, bgr, image.component == 4 ? cv::COLOR_RGBA2BGR : cv::COLOR_RGB2BGR);
    return bgr;
}

}  // namespace avatarbooth
