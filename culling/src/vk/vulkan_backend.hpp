#pragma once
// Internal: the Vulkan backend's factory. Vulkan headers stay behind culling/src.
#include "culling/core/backend.hpp"

#include <memory>
#include <string>

namespace lc {
// `device`: index or case-insensitive name substring; empty: LIGHTCULL_DEVICE,
// else the first discrete GPU, else the first device. Throws DeviceError with a
// clear message when Vulkan or a matching device is unavailable.
std::unique_ptr<CullBackend> makeVulkanBackend(const std::string& device);
// Names of the physical devices Vulkan reports (empty when none / no loader).
std::vector<std::string> vulkanDeviceNames();
} // namespace lc
