// avatar.usdz: the avatar for iOS's AR Quick Look, written by the booth itself (Debian has no USD library).
//
// A USDZ file is a zip archive read in place (Pixar's "Usdz File Format Specification"): every file stored
// without compression or encryption, each file's data starting at a multiple of 64 bytes from the start of the
// archive, the first file the default layer. Here the layer is USDA text (avatar.usda: one Xform "avatar" holding
// a Mesh "head" and a UsdPreviewSurface material) and the second file is its texture (texture.jpg), the same JPEG
// the glb carries. The mesh is the glb's too, vertex for vertex: positions in metres (metersPerUnit = 1, y up),
// normals and texture coordinates per vertex (st with t flipped: USD's (0,0) is the image's bottom-left corner,
// glTF's the top-left), counter-clockwise triangles (USD's default rightHanded orientation).
//
// It belongs beside the glb writer in fit/export/; it lives in booth/ while that folder is being changed.
#pragma once

#include "fit/head/mesh.h"
#include "fit/parts/avatar_part.h"

#include <opencv2/core.hpp>

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace avatarbooth {

// The USDA layer alone (for tests and for reading): `textureFile` is the texture's name inside the archive, empty
// for an untextured, skin-coloured material.
std::string encodeUsda(const Mesh& mesh, const std::string& textureFile);

// The .usdz bytes: the layer and `texture` (BGR, as a JPEG). Throws BoothError(Internal) for an empty mesh.
std::string encodeUsdz(const Mesh& mesh, const cv::Mat& texture);

// The avatar's parts (fit/parts/avatar_part.h) in one archive: the first part as the head above (Mesh "head",
// material "skin", texture.jpg), each other one a Mesh and a Material named after it with its texture NAME.jpg, or
// NAME.png when its alpha counts: then the material's opacity is the texture's alpha (with opacityThreshold for
// MASK) and the mesh is double-sided.
std::string encodeUsdz(const std::vector<AvatarPart>& parts);

// The zip part alone: `files` (name, bytes) stored in order, each one's data 64-byte aligned (padding in the
// local header's extra field, id 0x1986 as Pixar's writer uses). Names must be plain ASCII.
std::string storeAlignedZip(const std::vector<std::pair<std::string, std::string_view>>& files);

}  // namespace avatarbooth
