// glTF 2.0 binary (.glb) export and import of a textured head mesh.
#pragma once

#include "fit/head/mesh.h"
#include "fit/parts/avatar_part.h"

#include <opencv2/core.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace avatarbooth {

// The glb as bytes: one mesh, one primitive (positions, normals, UVs, 32-bit indices), one PBR material whose
// base colour texture is `texture` (BGR) stored as a JPEG in the binary chunk. glTF's unit is the metre: the
// millimetre positions are scaled by 1/1000. An empty texture gives an untextured skin-coloured material.
std::string encodeGlb(const Mesh& mesh, const cv::Mat& texture, const std::string& name = "avatar");

// The avatar's parts (avatar_part.h) in one glb: per part one mesh (one primitive as above), one node named after
// it and one material with the part's alpha mode (MASK with its cutoff; MASK and BLEND double-sided, their textures
// PNG with alpha), all nodes in the one scene, in the parts' order.
std::string encodeGlb(const std::vector<AvatarPart>& parts);

// Writes encodeGlb(...) to path atomically.
void writeGlb(const std::filesystem::path& path, const Mesh& mesh, const cv::Mat& texture,
              const std::string& name = "avatar");

// Reads the first triangle primitive of a glb (positions in metres -> millimetres, TEXCOORD_0, indices).
// Throws BoothError(BadConfig) naming the file and what is missing.
Mesh readGlbMesh(const std::filesystem::path& path);

// Reads the base colour texture of the first material, or an empty Mat.
cv::Mat readGlbTexture(const std::filesystem::path& path);

}  // namespace avatarbooth
