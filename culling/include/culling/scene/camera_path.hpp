#pragma once
// Camera paths (docs/FORMATS.md, "Camera paths"): the cameras of a fly-through,
// one per frame, from a glTF file's camera animation or a JSON list of
// cameras. `lightcull hunt --path` judges every frame of one. Bad input is an
// InputError naming the file and the JSON path; nothing is allocated beyond
// what the file's bytes and `maxFrames` allow.

#include "culling/scene/scene.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace lc {

struct CameraPathFrame {
    double time = 0; // seconds: JSON the frame's "time" (default index / fps); glTF the animation's clock
    Camera camera;   // a full, valid camera (Camera::validate() is empty)
};

struct CameraPath {
    std::vector<CameraPathFrame> frames; // at least 1, times finite and non-decreasing
    // One line for logs: "12 cameras of path.json" / "animation 'Fly' of
    // level.glb: camera node 'Cam' (nodes[3]), 0..4.5 s at 30 fps, 136 frames".
    std::string description;
};

// The most frames loadCameraPath returns unless told otherwise.
constexpr std::size_t kCameraPathMaxFrames = 100000;

// Reads the camera path in `path`.
//
// `.gltf`/`.glb` (by extension, or the GLB magic whatever the extension): the
// animation that moves the scene's camera node, the node loadGltfScene reads
// for GltfReadOptions::camera == `camera` (empty: the first camera in the
// scene's node order). The animated translation, rotation and scale of that
// node and of its ancestors make its world matrix; LINEAR (rotations by
// slerp), STEP and CUBICSPLINE keys, clamped outside their times. Frames are
// sampled at `fps` from the first to the last key time of the channels that
// move the camera, both included. The first animation (by index) that moves
// it is used, and the description says when others do too; `animation` (a
// name or an index into `animations`) picks another. Each camera is `base`
// (projection, fov, near/far, resolution, tile) placed as loadGltfScene places
// a camera: at the node's origin, looking down its -Z with its +Y up, the
// target at base's target distance. Meshes and lights are not read.
//
// Anything else: JSON {"cameras": [{camera}, ...], "fps": 30}, each camera with
// the keys of the scene JSON's "camera" plus an optional "time" (seconds,
// default index / fps, fps the file's or else `fps`); keys a camera leaves
// out keep `base`'s values.
//
// Throws InputError naming the file and JSON path (and the line, for JSON):
// bad values, more than `maxFrames` frames (counted before any is made), a
// glTF without a camera node or without an animation that moves it (the
// message lists the animations present). SettingsError for `fps` outside
// (0, 1000], `maxFrames` 0, an invalid `base`, and an `animation` or `camera`
// that names none (or, by name, several).
CameraPath loadCameraPath(const std::string& path, const Camera& base, double fps = 30,
                          const std::string& animation = {}, std::size_t maxFrames = kCameraPathMaxFrames,
                          const std::string& camera = {});

} // namespace lc
