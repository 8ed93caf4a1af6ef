// The scene model: validity checks, the light radius, the camera's view
// matrix and the projection-kind names.

#include "culling/core/depth.hpp"
#include "culling/core/errors.hpp"
#include "culling/scene/scene.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace lc {

namespace {
bool finite3(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
std::string fmt(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}
} // namespace

// ---------------------------------------------------------------- Mesh

std::string Mesh::validate() const {
    if (positions.size() % 3 != 0)
        return "positions: count " + std::to_string(positions.size()) + " is not a multiple of 3";
    if (indices.size() % 3 != 0)
        return "indices: count " + std::to_string(indices.size()) + " is not a multiple of 3";
    for (std::size_t i = 0; i < positions.size(); ++i)
        if (!std::isfinite(positions[i]))
            return "positions: vertex " + std::to_string(i / 3) + " has a non-finite coordinate";
    const std::size_t nv = vertexCount();
    for (std::size_t i = 0; i < indices.size(); ++i)
        if (indices[i] >= nv)
            return "indices: triangle " + std::to_string(i / 3) + " refers to vertex " +
                   std::to_string(indices[i]) + " but there are " + std::to_string(nv) + " vertices";
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(transform[c][r])) return "transform: non-finite element";
    return {};
}

// ---------------------------------------------------------------- PointLight

// Inverse-square law: the received intensity at distance d is I*c/d^2 per
// channel; the light stops mattering where the brightest channel falls to
// I_min, i.e. max(I*c)/r^2 = I_min, so r = sqrt(max(I*c) / I_min).
double PointLight::radius() const {
    if (explicitRadius > 0.0) return explicitRadius;
    const double peak = std::max({intensity * color.r, intensity * color.g, intensity * color.b});
    return std::sqrt(peak / minIntensity);
}

std::string PointLight::validate() const {
    if (!finite3(position)) return "position: must be finite";
    if (!finite3(color)) return "color: must be finite";
    if (color.r < 0 || color.g < 0 || color.b < 0) return "color: each channel must be >= 0";
    if (!std::isfinite(intensity)) return "intensity: must be finite";
    if (intensity < 0) return "intensity: must be >= 0 (got " + fmt(intensity) + ")";
    if (!std::isfinite(explicitRadius)) return "radius: must be finite";
    if (explicitRadius < 0) return "radius: must be >= 0 (got " + fmt(explicitRadius) + ")";
    // I_min only defines the radius when no explicit radius is set, but it is
    // kept valid in both cases so that clearing the radius never yields NaN.
    if (!std::isfinite(minIntensity)) return "min_intensity: must be finite";
    if (minIntensity <= 0) return "min_intensity: must be > 0 (got " + fmt(minIntensity) + ")";
    // The shading passes sum intensity x colour / max(d^2, 1e-4) over up to a
    // million lights in float: 1e24 per light keeps every sum finite.
    if (const double peak = intensity * std::max({color.r, color.g, color.b}); peak > kMaxLightPower)
        return "intensity: intensity x colour is " + fmt(peak) + ", past " + fmt(kMaxLightPower) +
               " (the shading works in float)";
    // Radii past float range are culled (hard case tiny_min_intensity); an
    // infinite one is not a sphere.
    if (!std::isfinite(radius()))
        return "radius: the inverse-square radius sqrt(intensity x colour / min_intensity) is infinite: give the "
               "light a radius or a larger min_intensity";
    if (kind == LightKind::Spot) {
        if (!finite3(direction)) return "direction: must be finite";
        if (glm::length(direction) == 0.0) return "direction: must not be zero";
        if (!std::isfinite(outerAngleDeg) || !(outerAngleDeg > 0.0) || outerAngleDeg > 90.0)
            return "outer_angle_deg: must be in (0, 90] degrees (got " + fmt(outerAngleDeg) + ")";
        if (!std::isfinite(innerAngleDeg) || innerAngleDeg < 0.0 || innerAngleDeg > outerAngleDeg)
            return "inner_angle_deg: must be in [0, outer_angle_deg] degrees (got " + fmt(innerAngleDeg) + ")";
    } else if (kind != LightKind::Point) {
        return "type: unknown light kind";
    }
    return {};
}

const char* toString(LightKind k) { return k == LightKind::Spot ? "spot" : "point"; }

// ---------------------------------------------------------------- ProjectionKind

const char* toString(ProjectionKind k) {
    switch (k) {
    case ProjectionKind::Perspective: return "perspective";
    case ProjectionKind::PerspectiveGL: return "perspective_gl";
    case ProjectionKind::ReversedZ: return "reversed_z";
    case ProjectionKind::Orthographic: return "orthographic";
    case ProjectionKind::OrthographicGL: return "orthographic_gl";
    }
    return "unknown";
}

ProjectionKind projectionKindFromString(const std::string& s) {
    for (auto k : {ProjectionKind::Perspective, ProjectionKind::PerspectiveGL, ProjectionKind::ReversedZ,
                   ProjectionKind::Orthographic, ProjectionKind::OrthographicGL})
        if (s == toString(k)) return k;
    throw SettingsError("projection", "unknown projection '" + s +
                                          "' (valid: perspective, perspective_gl, reversed_z, "
                                          "orthographic, orthographic_gl)");
}

bool isOrthographic(ProjectionKind k) {
    return k == ProjectionKind::Orthographic || k == ProjectionKind::OrthographicGL;
}
bool isReversed(ProjectionKind k) { return k == ProjectionKind::ReversedZ; }

// ---------------------------------------------------------------- Camera

// World -> view: right-handed, camera at the origin looking down -Z, +Y up.
glm::dmat4 Camera::viewFromWorld() const { return glm::lookAt(position, target, up); }

std::string Camera::validate() const {
    if (!finite3(position)) return "camera.position: must be finite";
    if (!finite3(target)) return "camera.target: must be finite";
    if (!finite3(up)) return "camera.up: must be finite";
    const glm::dvec3 view = target - position;
    if (glm::length(view) == 0.0) return "camera.target: must differ from camera.position";
    if (glm::length(up) == 0.0) return "camera.up: must not be zero";
    // Parallel when |dir x up| is tiny relative to |dir||up| (sine of the
    // angle below 1e-9): lookAt would divide by ~0 and give NaNs.
    if (glm::length(glm::cross(view, up)) <= 1e-9 * glm::length(view) * glm::length(up))
        return "camera.up: must not be parallel to the view direction";
    if (!(fovYDeg > 0.0 && fovYDeg < 180.0))
        return "camera.fov_y_deg: must be in (0, 180) degrees (got " + fmt(fovYDeg) + ")";
    if (!(orthoHeight > 0.0) || !std::isfinite(orthoHeight))
        return "camera.ortho_height: must be finite and > 0 (got " + fmt(orthoHeight) + ")";
    if (!(nearPlane > 0.0) || !std::isfinite(nearPlane))
        return "camera.near: must be finite and > 0 (got " + fmt(nearPlane) + ")";
    if (std::isnan(farPlane)) return "camera.far: must be a number";
    if (std::isinf(farPlane)) {
        if (farPlane < 0 || projection != ProjectionKind::ReversedZ)
            return "camera.far: infinity is allowed only with the reversed_z projection";
    } else if (!(farPlane > nearPlane)) {
        return "camera.far: must be greater than camera.near (" + fmt(farPlane) +
               " <= " + fmt(nearPlane) + ")";
    }
    if (width < 1 || width > 16384) return "camera.width: must be in [1, 16384] (got " + std::to_string(width) + ")";
    if (height < 1 || height > 16384)
        return "camera.height: must be in [1, 16384] (got " + std::to_string(height) + ")";
    if (tileSize < 1 || tileSize > 256)
        return "camera.tile_size: must be in [1, 256] (got " + std::to_string(tileSize) + ")";
    return {};
}

// ---------------------------------------------------------------- Scene

std::size_t Scene::triangleCount() const {
    std::size_t n = 0;
    for (const auto& m : meshes) n += m.triangleCount();
    return n;
}

bool Scene::hasSpotLights() const {
    return std::any_of(lights.begin(), lights.end(), [](const PointLight& l) { return l.isSpot(); });
}

void Scene::validate() const {
    if (std::string e = camera.validate(); !e.empty()) {
        const auto colon = e.find(':');
        throw SettingsError(e.substr(0, colon), e.substr(colon + 2));
    }
    for (std::size_t i = 0; i < meshes.size(); ++i) {
        if (std::string e = meshes[i].validate(); !e.empty()) {
            const Mesh& m = meshes[i];
            const std::string file = m.sourcePath.empty() ? "<built-in mesh '" + m.name + "'>" : m.sourcePath;
            throw InputError(file, "meshes[" + std::to_string(i) + "]", 0, e);
        }
    }
    for (std::size_t i = 0; i < lights.size(); ++i)
        if (std::string e = lights[i].validate(); !e.empty()) throw LightError(i, lights[i].name, e);
}

std::pair<glm::dvec3, glm::dvec3> Scene::bounds() const {
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    bool any = false;
    for (const auto& m : meshes) {
        // Only vertices that triangles use: unused vertices (the bunny has
        // some) must not grow the bounds.
        for (std::uint32_t idx : m.indices) {
            if (idx >= m.vertexCount()) continue;
            const glm::dvec3 w = glm::dvec3(m.transform * glm::dvec4(glm::dvec3(m.vertex(idx)), 1.0));
            lo = glm::min(lo, w);
            hi = glm::max(hi, w);
            any = true;
        }
    }
    if (!any) return {glm::dvec3(0.0), glm::dvec3(0.0)};
    return {lo, hi};
}

} // namespace lc
