// Projection math for every ProjectionKind (see projection.hpp for the spaces).
//
// clipFromView is built from the GLM right-handed matrices, then
//   - for the *_GL kinds composed with z' = (z + w) / 2, so clip.z/clip.w is the
//     window depth (ndc + 1) / 2 an OpenGL depth buffer holds;
//   - for reversed-Z, the near/far roles are swapped (finite far) or the
//     infinite form d = near / viewDepth is used;
//   - finally y is negated: GLM's NDC y points up, Vulkan's points down.
//
// Closed forms of the window depth d as a function of view depth v (n = near,
// f = far), which depthParams() hands to GLSL as (A, B):
//   Perspective, PerspectiveGL:  d = f/(f-n) - f n / ((f-n) v)   (A = f/(f-n), B = -f n/(f-n))
//   ReversedZ (finite):          d = -n/(f-n) + f n / ((f-n) v)  (A = -n/(f-n), B = f n/(f-n))
//   ReversedZ (infinite far):    d = n / v                        (A = 0, B = n)
//   Orthographic, OrthographicGL: d = (v - n) / (f - n)           (A = -n/(f-n), B = 1/(f-n))
// The GL kinds store the same window depth as their [0,1] siblings: ((ndc+1)/2
// of the [-1,1] matrix simplifies to the [0,1] formula).
#include "culling/math/projection.hpp"

#include "culling/core/errors.hpp"

#include <glm/ext/matrix_clip_space.hpp>

#include <cmath>

namespace lc {

namespace {

// Row operation z' = (z + w) / 2 on a clip-from-view matrix (GLM is column-major:
// m[col][row]).
glm::dmat4 composeGlDepth(glm::dmat4 m) {
    for (int c = 0; c < 4; ++c) m[c][2] = 0.5 * (m[c][2] + m[c][3]);
    return m;
}

// (A, B) of the closed forms above, in double (depthParams() holds them as float).
glm::dvec2 depthAB(ProjectionKind kind, double n, double f) {
    switch (kind) {
    case ProjectionKind::Perspective:
    case ProjectionKind::PerspectiveGL: return {f / (f - n), -f * n / (f - n)};
    case ProjectionKind::ReversedZ:
        if (std::isinf(f)) return {0.0, n};
        return {-n / (f - n), f * n / (f - n)};
    case ProjectionKind::Orthographic:
    case ProjectionKind::OrthographicGL: return {-n / (f - n), 1.0 / (f - n)};
    }
    return {0.0, 1.0};
}

glm::dmat4 flipY(glm::dmat4 m) {
    for (int c = 0; c < 4; ++c) m[c][1] = -m[c][1];
    return m;
}

} // namespace

Projection::Projection(const Camera& cam)
    : kind_(cam.projection), near_(cam.nearPlane), far_(cam.farPlane),
      fovY_(glm::radians(cam.fovYDeg)), orthoHeight_(cam.orthoHeight), width_(cam.width),
      height_(cam.height) {
    if (!(near_ > 0.0) || !std::isfinite(near_))
        throw SettingsError("camera.near", "must be a finite number > 0");
    if (!(far_ > near_)) throw SettingsError("camera.far", "must be greater than camera.near");
    if (std::isinf(far_) && kind_ != ProjectionKind::ReversedZ)
        throw SettingsError("camera.far", "may be infinite only with the reversed-z projection");
    if (width_ == 0 || height_ == 0) throw SettingsError("camera.width", "resolution must be >= 1");

    const double aspect = double(width_) / double(height_);
    const double n = near_, f = far_;
    tanHalfY_ = std::tan(0.5 * fovY_);
    tanHalfX_ = tanHalfY_ * aspect;
    halfH_ = 0.5 * orthoHeight_;
    halfW_ = halfH_ * aspect;

    glm::dmat4 m(1.0);
    switch (kind_) {
    case ProjectionKind::Perspective:
        m = glm::perspectiveRH_ZO(fovY_, aspect, n, f);
        break;
    case ProjectionKind::PerspectiveGL:
        m = composeGlDepth(glm::perspectiveRH_NO(fovY_, aspect, n, f));
        break;
    case ProjectionKind::ReversedZ:
        if (std::isinf(f)) {
            // clip.z = n, clip.w = -z_view = v  =>  d = n / v.
            m = glm::perspectiveRH_ZO(fovY_, aspect, n, 2.0 * n);
            m[2][2] = 0.0;
            m[3][2] = n;
        } else {
            m = glm::perspectiveRH_ZO(fovY_, aspect, f, n); // swapped: near -> 1, far -> 0
        }
        break;
    case ProjectionKind::Orthographic:
        m = glm::orthoRH_ZO(-halfW_, halfW_, -halfH_, halfH_, n, f);
        break;
    case ProjectionKind::OrthographicGL:
        m = composeGlDepth(glm::orthoRH_NO(-halfW_, halfW_, -halfH_, halfH_, n, f));
        break;
    }
    clipFromView_ = flipY(m);
    const glm::dvec2 ab = depthAB(kind_, n, f);
    params_.ab_ortho_clear =
        vec4(float(ab.x), float(ab.y), orthographic() ? 1.0f : 0.0f, float(clearDepth()));
}

glm::dvec2 Projection::windowDepthAB() const { return depthAB(kind_, near_, far_); }

double Projection::viewDepthFromWindowDepth(double d) const {
    const glm::dvec2 ab = depthAB(kind_, near_, far_);
    return lcViewDepthFromWindowDepthD(d, ab.x, ab.y, orthographic());
}

double Projection::windowDepthFromViewDepth(double viewDepth) const {
    const glm::dvec2 ab = depthAB(kind_, near_, far_);
    return orthographic() ? ab.x + ab.y * viewDepth : ab.x + ab.y / viewDepth;
}

glm::dvec2 Projection::ndcFromPixel(glm::dvec2 pixel) const {
    return {2.0 * pixel.x / double(width_) - 1.0, 2.0 * pixel.y / double(height_) - 1.0};
}

glm::dvec3 Projection::viewPositionAt(glm::dvec2 pixel, double viewDepth) const {
    const glm::dvec2 ndc = ndcFromPixel(pixel);
    // NDC y points down, view y up.
    if (orthographic()) return {ndc.x * halfW_, -ndc.y * halfH_, -viewDepth};
    return {ndc.x * tanHalfX_ * viewDepth, -ndc.y * tanHalfY_ * viewDepth, -viewDepth};
}

glm::dvec3 Projection::viewPositionFromDepth(std::uint32_t px, std::uint32_t py, double d) const {
    return viewPositionAt({px + 0.5, py + 0.5}, viewDepthFromWindowDepth(d));
}

glm::dvec2 Projection::pixelFromView(const glm::dvec3& p) const {
    glm::dvec2 ndc;
    if (orthographic()) {
        ndc = {p.x / halfW_, -p.y / halfH_};
    } else {
        const double v = -p.z;
        ndc = {p.x / (v * tanHalfX_), -p.y / (v * tanHalfY_)};
    }
    return {(ndc.x + 1.0) * 0.5 * double(width_), (ndc.y + 1.0) * 0.5 * double(height_)};
}

} // namespace lc
