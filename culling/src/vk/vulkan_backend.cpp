// Placeholder until the Vulkan passes land (issue 3).
#include "vk/vulkan_backend.hpp"
#include "culling/errors.hpp"

namespace lc {
std::unique_ptr<CullBackend> makeVulkanBackend(const std::string&) {
    throw DeviceError("the Vulkan backend is not built yet");
}
std::vector<std::string> vulkanDeviceNames() { return {}; }
} // namespace lc
