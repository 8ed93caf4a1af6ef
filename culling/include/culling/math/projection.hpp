#pragma once
// Projection math for every ProjectionKind, in double precision.
//
// Conventions (see docs/ARCHITECTURE.md):
// - view space is right-handed, Y up, the camera looks down -Z; view depth is
//   -z_view and is positive in front of the camera.
// - clipFromView() returns the matrix BOTH rasterisers use. It already is in
//   Vulkan's convention: clip.y/clip.w points DOWN (top row of the framebuffer
//   has ndc y = -1) and clip.z/clip.w is the window depth in [0,1]. This is the
//   one place that handles GLM's y-up vs Vulkan's y-down flip.
// - pixel (px, py) has its centre at (px+0.5, py+0.5); pixel (0,0) is top-left.

#include "culling/vk/gpu_shared.h"
#include "culling/scene/scene.hpp"

#include <glm/glm.hpp>

namespace lc {

class Projection {
public:
    explicit Projection(const Camera& cam);

    ProjectionKind kind() const { return kind_; }
    bool orthographic() const { return isOrthographic(kind_); }
    double nearPlane() const { return near_; }
    double farPlane() const { return far_; }    // may be +inf (ReversedZ)
    std::uint32_t width() const { return width_; }
    std::uint32_t height() const { return height_; }

    // Window depth of "no geometry" (the depth buffer's clear value).
    double clearDepth() const { return isReversed(kind_) ? 0.0 : 1.0; }
    // True when window depth d is nearer than e (the depth test's LESS/GREATER).
    bool nearer(double d, double e) const { return isReversed(kind_) ? d > e : d < e; }

    // View -> Vulkan clip space (see the header comment).
    const glm::dmat4& clipFromView() const { return clipFromView_; }

    // The linearisation constants shared with GLSL (gpu_shared.h).
    DepthParams depthParams() const { return params_; }
    // (A, B) of window depth d = A + B / viewDepth (perspective kinds) or
    // A + B * viewDepth (orthographic kinds), in double.
    glm::dvec2 windowDepthAB() const;

    // Window depth d in [0,1] -> view depth (positive in front of the camera).
    double viewDepthFromWindowDepth(double d) const;
    double windowDepthFromViewDepth(double viewDepth) const;

    // Pixel-space coordinates (x right, y down, in pixels, continuous) ->
    // NDC x,y (x right, y down, [-1,1]).
    glm::dvec2 ndcFromPixel(glm::dvec2 pixel) const;
    // The view-space point seen at continuous pixel position `pixel` at view
    // depth `viewDepth`.
    glm::dvec3 viewPositionAt(glm::dvec2 pixel, double viewDepth) const;
    // View-space position of the pixel centre (px, py) holding window depth d.
    glm::dvec3 viewPositionFromDepth(std::uint32_t px, std::uint32_t py, double d) const;
    // View-space point -> continuous pixel position (x right, y down).
    // Precondition for perspective: viewDepth > 0.
    glm::dvec2 pixelFromView(const glm::dvec3& pView) const;

private:
    ProjectionKind kind_;
    double near_, far_, fovY_, orthoHeight_;
    std::uint32_t width_, height_;
    double tanHalfY_, tanHalfX_;   // perspective
    double halfH_, halfW_;         // orthographic, world units
    glm::dmat4 clipFromView_;
    DepthParams params_;
};

} // namespace lc
