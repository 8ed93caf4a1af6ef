// View-space lights and the backend registry.
#include "culling/core/backend.hpp"
#include "culling/core/limits.hpp"

#include "culling/core/errors.hpp"
#include "culling/truth/shade.hpp"
#include "vk/vulkan_backend.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

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

std::uint32_t listsPerTileOf(Algorithm algorithm, std::uint32_t cells, bool cellLists) {
    if (algorithm == Algorithm::HalfZ) return 2;
    if (algorithm == Algorithm::Clustered || (algorithm == Algorithm::TwoPointFiveD && cellLists)) return cells;
    return 1;
}

std::uint32_t listsPerTileOf(const CullSettings& settings, bool cellLists) {
    return settings.clusterLists() ? settings.cells : listsPerTileOf(settings.algorithm, settings.cells, cellLists);
}

double cameraFarDepth(const Projection& proj, const ViewLights& lights, SpotTest spotTest) {
    if (std::isfinite(proj.farPlane())) return proj.farPlane();
    double lightFar = 0.0;
    for (std::size_t l = 0; l < lights.size(); ++l) {
        const BoundingSphere b = lights.cullSphere(l, spotTest);
        lightFar = std::max(lightFar, -b.center.z + b.radius);
    }
    return std::max(lightFar, proj.nearPlane());
}

CullFrame makeCullFrame(const DepthImage& depth, const Projection& proj, const TileGrid& grid,
                        const ViewLights& lights, const CullSettings& settings) {
    if (std::string e = settings.validate(); !e.empty()) throw SettingsError("settings", e);
    if (depth.width != proj.width() || depth.height != proj.height() ||
        depth.depth.size() != std::size_t(depth.width) * depth.height)
        throw Error("depth image is " + std::to_string(depth.width) + "x" + std::to_string(depth.height) +
                    ", the camera's resolution " + std::to_string(proj.width()) + "x" +
                    std::to_string(proj.height()));
    if (grid.width != proj.width() || grid.height != proj.height())
        throw Error("tile grid does not match the camera's resolution");
    if (lights.centers.size() != lights.radii.size()) throw Error("view lights: centres and radii differ in count");

    CullFrame f;
    f.grid = grid;
    f.listsPerTile = listsPerTileOf(settings);
    f.listTotal = settings.algorithm == Algorithm::All ? 1 : std::uint64_t(grid.tileCount()) * f.listsPerTile;
    f.cullSpheres.resize(lights.size());
    double lightFar = 0.0;
    for (std::size_t l = 0; l < lights.size(); ++l) {
        f.cullSpheres[l] = lights.cullSphere(l, settings.spotTest);
        lightFar = std::max(lightFar, -f.cullSpheres[l].center.z + f.cullSpheres[l].radius);
    }
    const bool farInfinite = !std::isfinite(proj.farPlane());
    f.cameraNear = f.clusterNear = proj.nearPlane();
    f.cameraFar = farInfinite ? std::max(lightFar, f.cameraNear) : proj.farPlane();
    f.clusterFar = farInfinite ? std::max(lightFar, 2.0 * f.cameraNear) : proj.farPlane();
    return f;
}

DepthPass CullBackend::depthPass(const Scene& scene, const Projection& proj) {
    const auto t0 = std::chrono::steady_clock::now();
    DepthPass d = renderDepthPass(scene, proj);
    const double wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (d.wallMs < 0) d.wallMs = wall;
    if (d.ms < 0) d.ms = d.wallMs;
    const DepthImage& img = d.image;
    if (img.width != proj.width() || img.height != proj.height() ||
        img.depth.size() != std::size_t(img.width) * img.height)
        throw Error("backend '" + name() + "' returned a " + std::to_string(img.width) + "x" +
                    std::to_string(img.height) + " depth image for a " + std::to_string(proj.width()) + "x" +
                    std::to_string(proj.height()) + " camera");
    return d;
}

namespace {

// The lights of `all` at `keep` (ascending), in that order.
ViewLights lightsAt(const ViewLights& all, const std::vector<std::uint32_t>& keep) {
    ViewLights v;
    const auto take = [&](const auto& from, auto& to) {
        if (from.empty()) return; // an optional per-light array stays absent
        to.reserve(keep.size());
        for (const std::uint32_t i : keep) to.push_back(from[i]);
    };
    take(all.centers, v.centers);
    take(all.radii, v.radii);
    take(all.power, v.power);
    take(all.spotAxes, v.spotAxes);
    take(all.spotAngles, v.spotAngles);
    take(all.shadingRanges, v.shadingRanges);
    return v;
}

// A result culled over the lights at `keep` names the scene's lights again:
// its indices mapped back (in order, so lists stay ascending), zbin's depth
// order gaining the lights left out after the kept ones (no bin reaches
// them: their positions are past every bin's range).
void nameSceneLights(CullResult& r, const std::vector<std::uint32_t>& keep, std::size_t lightCount) {
    for (std::uint32_t& i : r.lightIndices) i = keep[i];
    if (r.zbinOrder.empty()) return;
    for (std::uint32_t& i : r.zbinOrder) i = keep[i];
    std::vector<std::uint8_t> kept(lightCount, 0);
    for (const std::uint32_t i : keep) kept[i] = 1;
    for (std::uint32_t i = 0; i < lightCount; ++i)
        if (!kept[i]) r.zbinOrder.push_back(i);
    r.zbinRank.assign(lightCount, 0);
    for (std::uint32_t k = 0; k < r.zbinOrder.size(); ++k) r.zbinRank[r.zbinOrder[k]] = k;
}

} // namespace

CullResult CullBackend::cull(const DepthImage& depth, const Projection& proj, const TileGrid& grid,
                             const ViewLights& lights, const CullSettings& settings) {
    // A light limit: the engine keeps max-lights of the view's lights before
    // it culls (the nearest or the first, settings.limitKeep), so the cull
    // tests those alone and its time is what the engine pays (godot-4's 512
    // of forest's 4,096: culling all and dropping the rest afterwards timed
    // 55.9 ms on the CPU backend and 226 on lavapipe, against 15.4 and 32.4).
    std::vector<std::uint8_t> over = lightsOverLimit(lights, settings.maxLights, settings.limitKeep);
    std::vector<std::uint32_t> keep;
    for (std::uint32_t i = 0; i < over.size(); ++i)
        if (!over[i]) keep.push_back(i);
    const ViewLights keptLights = keep.empty() ? ViewLights{} : lightsAt(lights, keep);
    const ViewLights& culled = keep.empty() ? lights : keptLights;
    const CullFrame frame = makeCullFrame(depth, proj, grid, culled, settings);
    CullResult r = cullFrame(frame, depth, proj, culled, settings);
    if (!keep.empty()) nameSceneLights(r, keep, lights.size());
    r.algorithm = settings.algorithm;
    r.settings = settings;
    r.grid = frame.grid;
    r.listsPerTile = frame.listsPerTile;
    r.cameraNear = frame.cameraNear;
    r.cameraFar = frame.cameraFar;
    if (settings.clusterLists()) {
        r.clusterNear = frame.clusterNear;
        r.clusterFar = frame.clusterFar;
    }
    // The engine limits: one rule for every backend, on the lists its test made.
    applyListLimits(r, lights, settings, std::move(over));
    return r;
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
