// View-space lights and the backend registry.
#include "culling/core/backend.hpp"

#include "culling/core/errors.hpp"
#include "culling/truth/shade.hpp"
#include "vk/vulkan_backend.hpp"

#include <chrono>

namespace lc {

ViewLights makeViewLights(const Scene& scene) {
    ViewLights out;
    const glm::dmat4 viewFromWorld = scene.camera.viewFromWorld();
    out.centers.reserve(scene.lights.size());
    out.radii.reserve(scene.lights.size());
    out.power.reserve(scene.lights.size());
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        const PointLight& l = scene.lights[i];
        if (std::string e = l.validate(); !e.empty()) throw LightError(i, l.name, e);
        // viewFromWorld is rigid (rotation + translation), so radii carry over unchanged.
        out.centers.push_back(glm::dvec3(viewFromWorld * glm::dvec4(l.position, 1.0)));
        out.radii.push_back(l.radius());
        out.power.push_back(l.color * l.intensity);
        if (l.explicitRadius > 0.0) {
            if (out.shadingRanges.empty()) out.shadingRanges.assign(scene.lights.size(), 0.0);
            out.shadingRanges[i] = l.explicitRadius;
        }
        if (l.isSpot()) {
            if (out.spotAngles.empty()) {
                out.spotAxes.assign(scene.lights.size(), glm::dvec3(0.0, 0.0, -1.0));
                out.spotAngles.assign(scene.lights.size(), 0.0);
            }
            // Directions rotate with the view matrix's upper 3x3 (no translation).
            out.spotAxes[i] = glm::normalize(glm::dmat3(viewFromWorld) * l.direction);
            out.spotAngles[i] = glm::radians(l.outerAngleDeg);
        }
    }
    return out;
}

std::vector<float> CullBackend::shade(const ShadeInputs& in, const ViewLights& lights, const CullResult* culled) {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<float> rgb = shadeCpu(in, lights, culled);
    lastShadeMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return rgb;
}

std::vector<std::string> availableBackends() {
    std::vector<std::string> names{"cpu"};
    if (!vulkanDeviceNames().empty()) names.push_back("vulkan");
    return names;
}

std::unique_ptr<CullBackend> makeBackend(const std::string& name, const std::string& device) {
    if (name == "cpu") return makeCpuBackend();
    if (name == "vulkan") return makeVulkanBackend(device);
    std::string known;
    for (const auto& b : availableBackends()) known += (known.empty() ? "" : ", ") + b;
    throw Error("unknown backend '" + name + "' (available: " + known + ")");
}

} // namespace lc
