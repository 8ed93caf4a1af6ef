#pragma once
// A culling backend: the depth pre-pass and the culling pass on one device.
// The CPU backend is the double-precision reference; the Vulkan backend (where
// a device exists) runs the same passes as compute and raster work.

#include "culling/core/cull_result.hpp"
#include "culling/core/depth.hpp"
#include "culling/math/spot_tests.hpp"

#include <memory>
#include <string>
#include <vector>

namespace lc {

struct ShadeInputs; // culling/truth/shade.hpp

// Lights transformed to view space with their radii, the input of every pass.
// centers/radii are each light's range sphere (a spot light's apex sphere).
struct ViewLights {
    std::vector<glm::dvec3> centers; // view space
    std::vector<double> radii;
    std::vector<glm::dvec3> power;   // colour * intensity (linear RGB), for shading
    // Spot lights (docs/SPOT_LIGHTS.md): both empty when no light is a spot
    // (then every light is a point light); otherwise one entry per light, and
    // spotAngles[i] == 0 marks light i as a point light.
    std::vector<glm::dvec3> spotAxes; // view space, unit length
    std::vector<double> spotAngles;   // outer half-angle in radians, (0, pi/2]
    // Lights with an explicit range (a glTF `range`, a scene JSON `radius`):
    // one entry per light, the range (> 0) where the light's shading falls to
    // zero, 0 for a light whose radius is its inverse-square cut-off; empty
    // when no light has a range. Shading only: culling uses `radii`.
    std::vector<double> shadingRanges;
    std::size_t size() const { return radii.size(); }
    bool isSpot(std::size_t i) const { return i < spotAngles.size() && spotAngles[i] > 0.0; }
    // Light i's shading range, 0 when its light has none (shadingRanges).
    double shadingRange(std::size_t i) const { return i < shadingRanges.size() ? shadingRanges[i] : 0.0; }
    // Light i's cone. Precondition: isSpot(i).
    SpotCone spotCone(std::size_t i) const {
        return makeSpotCone(centers[i], spotAxes[i], radii[i], spotAngles[i]);
    }
    // The sphere a culling pass tests for light i under `test`: the range
    // sphere for point lights, spotCullSphere for spot lights.
    BoundingSphere cullSphere(std::size_t i, SpotTest test) const {
        return isSpot(i) ? spotCullSphere(test, spotCone(i)) : BoundingSphere{centers[i], radii[i]};
    }
};
// Validates every light (LightError naming it) and transforms it to view space.
ViewLights makeViewLights(const Scene& scene);

// One frame's culling as every pass and every diagnostic sees it, worked out
// once (makeCullFrame) and carried by the result: the grid, how many lists a
// tile has, and the depth ranges that do not come from the depth image.
struct CullFrame {
    TileGrid grid;
    std::uint32_t listsPerTile = 1; // listsPerTileOf(settings)
    std::uint64_t listTotal = 1;    // `all`: 1; else tiles x listsPerTile
    // The camera's view-depth range of naive and zbin's screen-space test
    // (and the camera frustum overlay): near..far, an infinite far replaced by
    // the farthest depth a light's culling sphere reaches (at least near).
    double cameraNear = 0, cameraFar = 0;
    // clustered: the slices' range; near..far, an infinite far replaced by
    // that reach (at least twice near).
    double clusterNear = 0, clusterFar = 0;
    // Per light: the sphere the passes test (ViewLights::cullSphere under
    // settings.spotTest).
    std::vector<BoundingSphere> cullSpheres;
};

// The far view depth of the camera range that `naive` and zbin's masks (and
// the camera frustum overlay) use: the far plane, or, when it is infinite
// (reversed-Z), the farthest depth any light's culling sphere
// (ViewLights::cullSphere under `spotTest`) reaches, never below the near
// plane. CullFrame::cameraFar; a result carries it as cameraFar.
double cameraFarDepth(const Projection& proj, const ViewLights& lights, SpotTest spotTest = SpotTest::ApexSphere);

// Lists per tile of an algorithm: halfz 2, clustered `cells` slices, 2.5d
// with one list per cell (custom culling's cells:N) `cells`, else 1.
std::uint32_t listsPerTileOf(Algorithm algorithm, std::uint32_t cells, bool cellLists = false);
// The same for full settings (raster with proxy-depth slices has clusters).
std::uint32_t listsPerTileOf(const CullSettings& settings, bool cellLists = false);

// Checks a cull's inputs (settings, the depth image and the grid against the
// camera's resolution, the lights' arrays) and builds its frame. Throws
// SettingsError for settings, Error for inputs that do not fit together.
CullFrame makeCullFrame(const DepthImage& depth, const Projection& proj, const TileGrid& grid,
                        const ViewLights& lights, const CullSettings& settings);

// One depth pre-pass, as CullBackend::depthPass returns it: the image and
// what it cost. Whoever ran it owns these figures (no later result is stamped
// with them behind its back).
struct DepthPass {
    DepthImage image;
    double ms = -1;     // as the backend times it (timingMethod())
    double wallMs = -1; // CPU wall clock around its submission, the readback included
    // The scene's triangles and those rasterised (the Vulkan backend leaves
    // out the faces of closed solids turned away from the camera; the CPU
    // rasteriser draws every triangle).
    std::size_t triangles = 0, trianglesDrawn = 0;
};

class CullBackend {
public:
    virtual ~CullBackend() = default;
    virtual std::string name() const = 0;       // "cpu", "vulkan"
    virtual std::string deviceName() const = 0;
    // Depth pre-pass of the scene through the camera: the image, its time
    // and triangles. Checks that the image fits the camera.
    DepthPass depthPass(const Scene& scene, const Projection& proj);
    // The image alone, for callers that time nothing.
    DepthImage renderDepth(const Scene& scene, const Projection& proj) { return depthPass(scene, proj).image; }
    // Culling pass over a depth image (any backend's). Fills result timings.
    // Validates and builds the frame once (makeCullFrame), then the backend's
    // cullFrame culls it; the result carries the frame's grid, lists per tile
    // and depth ranges, which diagnostics read instead of working them out.
    CullResult cull(const DepthImage& depth, const Projection& proj, const TileGrid& grid, const ViewLights& lights,
                    const CullSettings& settings);
    virtual std::string timingMethod() const = 0;
    // CPU wall-clock milliseconds of the last cull() around its submissions
    // (equal to its cullMs where that is the timing method; -1: not run).
    double lastCullWallMs() const { return lastCullWallMs_; }
    // Bits per light index in which the last cull's lists came back from the
    // device: 16 where a GPU wrote them so (at most 65,536 lights), else 32.
    // The result holds 32-bit indices either way.
    unsigned lastDeviceIndexBits() const { return lastIndexBits_; }
    // Most device memory (buffers and images, as allocated) alive at once
    // since the last resetPeakDeviceBytes(); 0 for backends without a device.
    virtual std::size_t peakDeviceBytes() const { return 0; }
    virtual void resetPeakDeviceBytes() {}
    // Device memory allocations made so far (0 for backends without a device).
    virtual std::uint64_t deviceAllocations() const { return 0; }
    // Lambert shading pass (culling/truth/shade.hpp) over a G-buffer built by
    // makeShadeInputs: each geometry pixel shaded from the lights of its list
    // in `culled` (null: every light in index order). Returns RGB, 3 floats per
    // pixel, background 0. Sets lastShadeMs(), timed like cull(). The default
    // is the CPU reference (shadeCpu) timed by steady_clock.
    virtual std::vector<float> shade(const ShadeInputs& in, const ViewLights& lights, const CullResult* culled);
    double lastShadeMs() const { return lastShadeMs_; }

protected:
    // The backend's depth pre-pass (depthPass checks what it returns).
    virtual DepthPass renderDepthPass(const Scene& scene, const Projection& proj) = 0;
    // The culling pass of a frame makeCullFrame built from these inputs.
    virtual CullResult cullFrame(const CullFrame& frame, const DepthImage& depth, const Projection& proj,
                                 const ViewLights& lights, const CullSettings& settings) = 0;

    double lastCullWallMs_ = -1;
    unsigned lastIndexBits_ = 32;
    double lastShadeMs_ = -1;
};

std::unique_ptr<CullBackend> makeCpuBackend();

// Names of the backends this build can create ("cpu", and "vulkan" when built
// with Vulkan). makeBackend throws Error with a clear message when the backend
// is unknown or (Vulkan) no device matches `device` (index or name substring;
// empty: LIGHTCULL_DEVICE, else the first discrete GPU, else the first device).
std::vector<std::string> availableBackends();
// How many Vulkan instances this process has opened (a backend's, and one
// each time availableBackends() or the device list looks for devices): each
// starts the drivers, tens of milliseconds on lavapipe, so an interactive
// path must not open one per edit.
std::uint64_t vulkanInstancesOpened();
// The culling pipelines (one per pass and specialisation) the Vulkan backends
// of this process have made, and how many they hold now. A backend keeps the
// 256 it used last: on lavapipe each holds megabytes of compiled code.
struct VulkanPipelineCount {
    std::uint64_t made = 0, held = 0;
};
VulkanPipelineCount vulkanCullPipelines();
std::unique_ptr<CullBackend> makeBackend(const std::string& name, const std::string& device = {});

} // namespace lc
