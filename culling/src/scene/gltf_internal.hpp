// Internals of the glTF reader (gltf_io.cpp) shared with the camera-path
// reader (camera_path.cpp), so that both parse, check and walk a file the same
// way and pick the same camera node. Not a public header: it exposes tinygltf.
#pragma once

#include "culling/scene/gltf_io.hpp"

#include <tiny_gltf.h>

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace lc {

// Reads and parses a .gltf or .glb (by extension or the GLB magic) with every
// container check loadGltfScene makes; warnings go to `rep`.
tinygltf::Model parseGltfModel(const std::string& path, GltfReadReport& rep);

// A node of the shown scene with its world matrix (the static one, from the
// nodes' matrix or translation/rotation/scale).
struct GltfPlacedNode {
    int node;
    glm::dmat4 world;
};
// The nodes of the scene loadGltfScene shows, in pre-order (children in
// order), each reached once: a cycle or a node with two parents is an
// InputError. Every child index of a returned node is valid and returned.
std::vector<GltfPlacedNode> walkGltfScene(const std::string& path, const tinygltf::Model& model);

// nodes[n]'s local matrix from `matrix` or translation * rotation * scale,
// each checked (counts, finite, non-zero quaternion, affine matrix).
glm::dmat4 gltfLocalMatrix(const std::string& path, const tinygltf::Model& model, std::size_t n);

// The placed camera node loadGltfScene reads for GltfReadOptions::camera ==
// `camera` (a camera or camera-node name, or an index into `cameras`; empty:
// the first in node order), as an index into `placed`; -1 when the scene
// places no camera. Throws SettingsError("camera", ...) for a name or index
// that picks none or several, InputError for a bad camera index on a node.
int chooseGltfCamera(const std::string& path, const tinygltf::Model& model,
                     const std::vector<GltfPlacedNode>& placed, const std::string& camera);

// A camera node's placement read from its world matrix as glTF defines it:
// the origin, the -Z axis as the view direction and +Y as up, both
// normalised. False when either axis has no positive length (a singular
// transform, or NaN); infinite values pass and fail Camera::validate() later.
struct GltfCameraPose {
    glm::dvec3 position, forward, up;
};
bool gltfCameraPose(const glm::dmat4& world, GltfCameraPose& pose);

// Bytes [offset, offset + elemSize + stride * (count - 1)) of bufferViews[view],
// checked with 64-bit arithmetic against the view and the view against its
// buffer; `stride` is the view's byteStride or, when 0, `elemSize`. Errors
// name `field` ("accessors[3]") and `what` the elements are.
struct GltfByteSpan {
    const unsigned char* data;
    std::size_t stride;
};
GltfByteSpan gltfViewSpan(const std::string& path, const tinygltf::Model& model, int view, std::uint64_t offset,
                          std::uint64_t count, std::size_t elemSize, const std::string& field, const std::string& what);

} // namespace lc
