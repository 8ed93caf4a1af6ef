#pragma once
// Shared by the gpu-tier tests: every test runs with the Khronos validation
// layer (synchronisation validation included) and fails on any message.
//
// LIGHTCULL_VALIDATION=1 is set before the first Vulkan instance is created;
// one backend is shared per test executable (instance creation with the layer
// costs a few hundred milliseconds on lavapipe).
#include "culling/core/backend.hpp"
#include "culling/core/depth.hpp"
#include "vk/validation.hpp"
#include "vk/vulkan_backend.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>

namespace lc::gputest {

inline CullBackend& vulkan() {
    static std::unique_ptr<CullBackend> backend = [] {
        setenv("LIGHTCULL_VALIDATION", "1", 1);
        return makeVulkanBackend("");
    }();
    return *backend;
}

// Mesa's lavapipe (a CPU device, with its loop cap; vulkan_backend.cpp).
inline bool vulkanIsCpuDevice() { return vulkan().deviceName().rfind("llvmpipe", 0) == 0; }

inline std::string joinedMessages() {
    std::string s;
    for (const auto& m : vk::validationMessages()) s += m + "\n";
    return s;
}

// The gpu tier's fixture: one frame's culling inputs from its scene (the
// projection, the grid of its camera's tiles, the view lights and a depth
// image: the shared Vulkan backend's by default, `depthFrom`'s, or the CPU
// rasteriser's for nullptr). A test states its scene and culls f on both
// backends: f.cull(*cpu, settings), f.cull(vulkan(), settings).
struct Frame {
    Scene scene;
    Projection proj;
    TileGrid grid;
    ViewLights lights;
    DepthImage depth;

    explicit Frame(Scene s) : Frame(std::move(s), &vulkan()) {}
    Frame(Scene s, CullBackend* depthFrom)
        : scene(std::move(s)), proj(scene.camera),
          grid(TileGrid::make(scene.camera.width, scene.camera.height, scene.camera.tileSize)),
          lights(makeViewLights(scene)),
          depth(depthFrom ? depthFrom->renderDepth(scene, proj) : rasterizeDepthCpu(scene, proj)) {}
    CullResult cull(CullBackend& backend, const CullSettings& settings) const {
        return backend.cull(depth, proj, grid, lights, settings);
    }
};

// Base fixture: asserts that the test left no validation message behind.
class GpuTest : public ::testing::Test {
protected:
    void SetUp() override { setenv("LIGHTCULL_VALIDATION", "1", 1); }
    void TearDown() override {
        EXPECT_TRUE(vk::validationMessages().empty()) << "validation messages:\n" << joinedMessages();
        vk::clearValidationMessages();
    }
};

} // namespace lc::gputest
