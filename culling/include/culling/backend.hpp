#pragma once
// A culling backend: the depth pre-pass and the culling pass on one device.
// The CPU backend is the double-precision reference; the Vulkan backend (where
// a device exists) runs the same passes as compute and raster work.

#include "culling/cull_result.hpp"
#include "culling/depth.hpp"

#include <memory>
#include <string>
#include <vector>

namespace lc {

// Lights transformed to view space with their radii, the input of every pass.
struct ViewLights {
    std::vector<glm::dvec3> centers; // view space
    std::vector<double> radii;
    std::vector<glm::dvec3> power;   // colour * intensity (linear RGB), for shading
    std::size_t size() const { return radii.size(); }
};
// Validates every light (LightError naming it) and transforms it to view space.
ViewLights makeViewLights(const Scene& scene);

class CullBackend {
public:
    virtual ~CullBackend() = default;
    virtual std::string name() const = 0;       // "cpu", "vulkan"
    virtual std::string deviceName() const = 0;
    // Depth pre-pass of the scene through the camera. Sets lastDepthMs().
    virtual DepthImage renderDepth(const Scene& scene, const Projection& proj) = 0;
    // Culling pass over a depth image (any backend's). Fills result timings.
    virtual CullResult cull(const DepthImage& depth, const Projection& proj, const TileGrid& grid,
                            const ViewLights& lights, const CullSettings& settings) = 0;
    double lastDepthMs() const { return lastDepthMs_; }
    virtual std::string timingMethod() const = 0;

protected:
    double lastDepthMs_ = -1;
};

std::unique_ptr<CullBackend> makeCpuBackend();

// Names of the backends this build can create ("cpu", and "vulkan" when built
// with Vulkan). makeBackend throws Error with a clear message when the backend
// is unknown or (Vulkan) no device matches `device` (index or name substring;
// empty: LIGHTCULL_DEVICE, else the first discrete GPU, else the first device).
std::vector<std::string> availableBackends();
std::unique_ptr<CullBackend> makeBackend(const std::string& name, const std::string& device = {});

} // namespace lc
