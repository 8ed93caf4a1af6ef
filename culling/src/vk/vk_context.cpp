#include "vk/vk_context.hpp"

#include "vk/validation.hpp"
#include "culling/capture/renderdoc_capture.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <limits>
#include <cstdlib>
#include <cstring>

// Vulkan create-info structs are value-initialised as {VK_STRUCTURE_TYPE_...}:
// the remaining members are zero on purpose.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

namespace lc::vk {

const char* resultName(VkResult r) {
    switch (r) {
#define LC_CASE(x) case x: return #x;
        LC_CASE(VK_SUCCESS) LC_CASE(VK_NOT_READY) LC_CASE(VK_TIMEOUT) LC_CASE(VK_INCOMPLETE)
        LC_CASE(VK_ERROR_OUT_OF_HOST_MEMORY) LC_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        LC_CASE(VK_ERROR_INITIALIZATION_FAILED) LC_CASE(VK_ERROR_DEVICE_LOST)
        LC_CASE(VK_ERROR_MEMORY_MAP_FAILED) LC_CASE(VK_ERROR_LAYER_NOT_PRESENT)
        LC_CASE(VK_ERROR_EXTENSION_NOT_PRESENT) LC_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
        LC_CASE(VK_ERROR_INCOMPATIBLE_DRIVER) LC_CASE(VK_ERROR_TOO_MANY_OBJECTS)
        LC_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED) LC_CASE(VK_ERROR_FRAGMENTED_POOL)
        LC_CASE(VK_ERROR_UNKNOWN) LC_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
        LC_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE) LC_CASE(VK_ERROR_FRAGMENTATION)
        LC_CASE(VK_ERROR_INVALID_SHADER_NV)
#undef LC_CASE
    default: return "VkResult(unknown)";
    }
}

void memoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags srcStage, VkAccessFlags srcAccess,
                   VkPipelineStageFlags dstStage, VkAccessFlags dstAccess) {
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = srcAccess;
    mb.dstAccessMask = dstAccess;
    vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 1, &mb, 0, nullptr, 0, nullptr);
}

void throwVkError(const char* call, VkResult r, const char* file, int line) {
    throw DeviceError(std::string("Vulkan call failed: ") + call + " returned " + resultName(r) + " (" +
                      resultName(r) + " = " + std::to_string(int(r)) + ") at " + file + ":" +
                      std::to_string(line));
}

namespace {

VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
    if (severity & (VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT)) {
        std::string m = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error: " : "warning: ";
        if (data && data->pMessageIdName) m += std::string(data->pMessageIdName) + ": ";
        if (data && data->pMessage) m += data->pMessage;
        recordValidationMessage(m);
    }
    return VK_FALSE; // never abort the call
}

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

bool hasExtension(const std::vector<VkExtensionProperties>& exts, const char* name) {
    return std::any_of(exts.begin(), exts.end(),
                       [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

std::vector<VkPhysicalDevice> enumerateDevices(VkInstance inst) {
    std::uint32_t n = 0;
    LC_VK(vkEnumeratePhysicalDevices(inst, &n, nullptr));
    std::vector<VkPhysicalDevice> devs(n);
    if (n) LC_VK(vkEnumeratePhysicalDevices(inst, &n, devs.data()));
    devs.resize(n);
    return devs;
}

// Picks the device per vulkan_backend.hpp's rule; throws naming what exists.
VkPhysicalDevice chooseDevice(const std::vector<VkPhysicalDevice>& devs, std::string want) {
    if (devs.empty()) throw DeviceError("no Vulkan device found (is mesa-vulkan-drivers installed?)");
    if (want.empty()) {
        if (const char* env = std::getenv("LIGHTCULL_DEVICE")) want = env;
    }
    std::vector<std::string> names;
    for (auto d : devs) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(d, &p);
        names.push_back(p.deviceName);
    }
    auto listing = [&] {
        std::string s;
        for (std::size_t i = 0; i < names.size(); ++i) s += (i ? ", " : "") + std::to_string(i) + ": " + names[i];
        return s;
    };
    if (!want.empty()) {
        bool digits = std::all_of(want.begin(), want.end(), [](unsigned char c) { return std::isdigit(c); });
        if (digits) {
            unsigned long idx = std::strtoul(want.c_str(), nullptr, 10);
            if (idx >= devs.size())
                throw DeviceError("Vulkan device index " + want + " out of range (devices: " + listing() + ")");
            return devs[idx];
        }
        for (std::size_t i = 0; i < devs.size(); ++i)
            if (lower(names[i]).find(lower(want)) != std::string::npos) return devs[i];
        throw DeviceError("no Vulkan device matches '" + want + "' (devices: " + listing() + ")");
    }
    for (auto d : devs) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(d, &p);
        if (p.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU) return d;
    }
    return devs.front();
}

// Creates an instance (with validation when requested). Returns the instance
// and whether VK_EXT_debug_utils is enabled.
// The messenger of every validation message (warnings and errors, general,
// validation and performance) into debugCallback: chained into instance
// creation for its own messages, then created for the instance's life.
VkDebugUtilsMessengerCreateInfoEXT messengerInfo() {
    VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                      VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    mci.pfnUserCallback = debugCallback;
    return mci;
}

std::atomic<bool> g_instanceCreated{false};
std::atomic<std::uint64_t> g_instancesOpened{0};

VkInstance createInstance(bool& debugUtils, bool& validation, bool forceValidation) {
    g_instanceCreated = true;
    ++g_instancesOpened;
    std::uint32_t n = 0;
    LC_VK(vkEnumerateInstanceExtensionProperties(nullptr, &n, nullptr));
    std::vector<VkExtensionProperties> exts(n);
    LC_VK(vkEnumerateInstanceExtensionProperties(nullptr, &n, exts.data()));
    std::vector<const char*> enabled;
    debugUtils = hasExtension(exts, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);

    validation = validationRequested() || forceValidation;
    std::vector<const char*> layers;
    bool validationFeatures = false;
    if (validation) {
        std::uint32_t ln = 0;
        LC_VK(vkEnumerateInstanceLayerProperties(&ln, nullptr));
        std::vector<VkLayerProperties> lps(ln);
        LC_VK(vkEnumerateInstanceLayerProperties(&ln, lps.data()));
        const char* kLayer = "VK_LAYER_KHRONOS_validation";
        bool found = std::any_of(lps.begin(), lps.end(),
                                 [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, kLayer) == 0; });
        if (!found)
            throw DeviceError("LIGHTCULL_VALIDATION=1 but VK_LAYER_KHRONOS_validation is not installed "
                              "(Debian: vulkan-validationlayers)");
        layers.push_back(kLayer);
        std::uint32_t en = 0;
        LC_VK(vkEnumerateInstanceExtensionProperties(kLayer, &en, nullptr));
        std::vector<VkExtensionProperties> lexts(en);
        LC_VK(vkEnumerateInstanceExtensionProperties(kLayer, &en, lexts.data()));
        validationFeatures = hasExtension(lexts, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
        if (!debugUtils) debugUtils = hasExtension(lexts, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        if (validationFeatures) enabled.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
        if (!debugUtils)
            throw DeviceError("LIGHTCULL_VALIDATION=1 needs VK_EXT_debug_utils to record messages");
    }
    if (debugUtils) enabled.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);

    std::uint32_t apiVersion = VK_API_VERSION_1_1;
    auto enumVersion = reinterpret_cast<PFN_vkEnumerateInstanceVersion>(
        vkGetInstanceProcAddr(nullptr, "vkEnumerateInstanceVersion"));
    if (enumVersion) {
        std::uint32_t v = 0;
        if (enumVersion(&v) == VK_SUCCESS && v >= VK_API_VERSION_1_3) apiVersion = VK_API_VERSION_1_3;
    }
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "LightCull Studio";
    app.pEngineName = "lightcull";
    app.apiVersion = apiVersion;

    // Chain: messenger (catches instance creation messages) -> validation features.
    VkValidationFeatureEnableEXT syncEnable = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
    features.enabledValidationFeatureCount = 1;
    features.pEnabledValidationFeatures = &syncEnable;
    VkDebugUtilsMessengerCreateInfoEXT mci = messengerInfo();
    if (validation && validationFeatures) mci.pNext = &features;

    VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ci.pApplicationInfo = &app;
    ci.enabledLayerCount = std::uint32_t(layers.size());
    ci.ppEnabledLayerNames = layers.data();
    ci.enabledExtensionCount = std::uint32_t(enabled.size());
    ci.ppEnabledExtensionNames = enabled.data();
    if (validation) ci.pNext = &mci;
    VkInstance inst = VK_NULL_HANDLE;
    const VkResult r = vkCreateInstance(&ci, nullptr, &inst);
    if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
        throw DeviceError(std::string("no Vulkan driver found: vkCreateInstance returned "
                                      "VK_ERROR_INCOMPATIBLE_DRIVER at ") +
                          __FILE__ + ":" + std::to_string(__LINE__) +
                          " (install mesa-vulkan-drivers for lavapipe, or use the cpu backend)");
    if (r != VK_SUCCESS) throwVkError("vkCreateInstance(&ci, nullptr, &inst)", r, __FILE__, __LINE__);
    if (validation) {
        markValidationLayerActive();
        if (validationFeatures) markSyncValidationActive();
    }
    return inst;
}

} // namespace

std::vector<std::string> physicalDeviceNames() {
    std::vector<std::string> out;
    g_instanceCreated = true;
    ++g_instancesOpened;
    try {
        VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
        app.apiVersion = VK_API_VERSION_1_1;
        VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
        ci.pApplicationInfo = &app;
        VkInstance inst = VK_NULL_HANDLE;
        if (vkCreateInstance(&ci, nullptr, &inst) != VK_SUCCESS) return out;
        std::uint32_t n = 0;
        if (vkEnumeratePhysicalDevices(inst, &n, nullptr) == VK_SUCCESS && n) {
            std::vector<VkPhysicalDevice> devs(n);
            if (vkEnumeratePhysicalDevices(inst, &n, devs.data()) == VK_SUCCESS)
                for (std::uint32_t i = 0; i < n; ++i) {
                    VkPhysicalDeviceProperties p;
                    vkGetPhysicalDeviceProperties(devs[i], &p);
                    out.push_back(p.deviceName);
                }
        }
        vkDestroyInstance(inst, nullptr);
    } catch (...) {
    }
    return out;
}

Context::Context(const ContextOptions& opt) : purpose_(opt.purpose) {
    if (const char* e = std::getenv("LIGHTCULL_VK_EMULATE_GPU")) emulateGpu_ = std::string(e) == "1";
    bool validation = false;
    instance_ = createInstance(debugUtils_, validation, opt.validation);
    try {
        if (validation) {
            const VkDebugUtilsMessengerCreateInfoEXT mci = messengerInfo();
            auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
            if (!create) throw DeviceError("vkCreateDebugUtilsMessengerEXT unavailable");
            LC_VK(create(instance_, &mci, nullptr, &messenger_));
        }
        if (debugUtils_) {
            setName_ = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
                vkGetInstanceProcAddr(instance_, "vkSetDebugUtilsObjectNameEXT"));
            beginLabel_ = reinterpret_cast<PFN_vkCmdBeginDebugUtilsLabelEXT>(
                vkGetInstanceProcAddr(instance_, "vkCmdBeginDebugUtilsLabelEXT"));
            endLabel_ = reinterpret_cast<PFN_vkCmdEndDebugUtilsLabelEXT>(
                vkGetInstanceProcAddr(instance_, "vkCmdEndDebugUtilsLabelEXT"));
            if (!beginLabel_ || !endLabel_) beginLabel_ = nullptr, endLabel_ = nullptr;
        }

        physical_ = chooseDevice(enumerateDevices(instance_), opt.device);
        vkGetPhysicalDeviceProperties(physical_, &props_);
        vkGetPhysicalDeviceMemoryProperties(physical_, &memProps_);
        if (props_.apiVersion < VK_API_VERSION_1_1)
            throw DeviceError(std::string("Vulkan device '") + props_.deviceName + "' is older than Vulkan 1.1");

        // Subgroup operations the culling passes rely on (compute stage).
        VkPhysicalDeviceSubgroupProperties sg{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
        VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
        p2.pNext = &sg;
        vkGetPhysicalDeviceProperties2(physical_, &p2);
        const VkSubgroupFeatureFlags need = VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT |
                                            VK_SUBGROUP_FEATURE_BALLOT_BIT;
        if (!(sg.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) || (sg.supportedOperations & need) != need)
            throw DeviceError(std::string("Vulkan device '") + props_.deviceName +
                              "' lacks subgroup basic/arithmetic/ballot operations in compute shaders");
        subgroupSize_ = std::max<std::uint32_t>(1, sg.subgroupSize);
        shuffle_ = (sg.supportedOperations & VK_SUBGROUP_FEATURE_SHUFFLE_BIT) != 0;

        std::uint32_t qn = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(physical_, &qn, nullptr);
        std::vector<VkQueueFamilyProperties> qf(qn);
        vkGetPhysicalDeviceQueueFamilyProperties(physical_, &qn, qf.data());
        bool found = false;
        for (std::uint32_t i = 0; i < qn && !found; ++i)
            if ((qf[i].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) ==
                (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) {
                queueFamily_ = i;
                found = true;
            }
        if (!found)
            throw DeviceError(std::string("Vulkan device '") + props_.deviceName +
                              "' has no queue family with both graphics and compute");
        timestampValidBits_ = qf[queueFamily_].timestampValidBits;
        timestamps_ = timestampValidBits_ > 0 && props_.limits.timestampPeriod > 0.0f &&
                      props_.limits.timestampComputeAndGraphics;

        // Full subgroups for compute (Vulkan 1.3 core feature): with the local
        // size equal to the subgroup size a workgroup is then exactly one subgroup.
        VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
        VkPhysicalDevice16BitStorageFeatures f16{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_16BIT_STORAGE_FEATURES};
        VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
        bool v13 = props_.apiVersion >= VK_API_VERSION_1_3;
        f2.pNext = &f16;
        if (v13) f16.pNext = &f13;
        vkGetPhysicalDeviceFeatures2(physical_, &f2);
        fullSubgroups_ = v13 && f13.computeFullSubgroups;
        index16_ = f16.storageBuffer16BitAccess == VK_TRUE;
        VkPhysicalDeviceVulkan13Features enable13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
        enable13.computeFullSubgroups = fullSubgroups_ ? VK_TRUE : VK_FALSE;
        enable13.subgroupSizeControl = (v13 && f13.subgroupSizeControl) ? VK_TRUE : VK_FALSE;
        VkPhysicalDevice16BitStorageFeatures enable16{
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_16BIT_STORAGE_FEATURES};
        enable16.storageBuffer16BitAccess = index16_ ? VK_TRUE : VK_FALSE;

        VkPhysicalDeviceFeatures f10{};
        vkGetPhysicalDeviceFeatures(physical_, &f10);
        int64_ = f10.shaderInt64 == VK_TRUE;
        VkPhysicalDeviceFeatures enable10{};
        enable10.shaderInt64 = int64_ ? VK_TRUE : VK_FALSE;
        fragmentStores_ = f10.fragmentStoresAndAtomics == VK_TRUE;
        enable10.fragmentStoresAndAtomics = fragmentStores_ ? VK_TRUE : VK_FALSE;
        // VK_EXT_conservative_rasterization where the device has it.
        std::vector<const char*> deviceExtensions;
        {
            std::uint32_t count = 0;
            vkEnumerateDeviceExtensionProperties(physical_, nullptr, &count, nullptr);
            std::vector<VkExtensionProperties> exts(count);
            vkEnumerateDeviceExtensionProperties(physical_, nullptr, &count, exts.data());
            for (const auto& e : exts)
                if (std::string(e.extensionName) == VK_EXT_CONSERVATIVE_RASTERIZATION_EXTENSION_NAME) conservative_ = true;
            if (std::getenv("LIGHTCULL_VK_NO_CONSERVATIVE")) conservative_ = false;
            if (conservative_) {
                VkPhysicalDeviceConservativeRasterizationPropertiesEXT cp{
                    VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_CONSERVATIVE_RASTERIZATION_PROPERTIES_EXT};
                VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
                p2.pNext = &cp;
                vkGetPhysicalDeviceProperties2(physical_, &p2);
                overestimation_ = cp.primitiveOverestimationSize;
                maxExtraOverestimation_ = cp.maxExtraPrimitiveOverestimationSize;
                deviceExtensions.push_back(VK_EXT_CONSERVATIVE_RASTERIZATION_EXTENSION_NAME);
            }
        }
        if (opt.robustAccess) {
            if (!f10.robustBufferAccess)
                throw DeviceError(std::string("Vulkan device '") + props_.deviceName + "' lacks robustBufferAccess");
            enable10.robustBufferAccess = VK_TRUE;
        }

        float prio = 1.0f;
        VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
        qci.queueFamilyIndex = queueFamily_;
        qci.queueCount = 1;
        qci.pQueuePriorities = &prio;
        VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
        dci.queueCreateInfoCount = 1;
        dci.pQueueCreateInfos = &qci;
        dci.pEnabledFeatures = &enable10;
        dci.enabledExtensionCount = std::uint32_t(deviceExtensions.size());
        dci.ppEnabledExtensionNames = deviceExtensions.data();
        dci.pNext = &enable16;
        if (v13) enable16.pNext = &enable13;
        LC_VK(vkCreateDevice(physical_, &dci, nullptr, &device_));
        vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);
        name(VK_OBJECT_TYPE_DEVICE, device_, "device");
        name(VK_OBJECT_TYPE_QUEUE, queue_, "queue");

        VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
        pci.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT | VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        pci.queueFamilyIndex = queueFamily_;
        VkCommandPool pool;
        LC_VK(vkCreateCommandPool(device_, &pci, nullptr, &pool));
        commandPool_ = CommandPoolHandle(device_, pool);
        name(VK_OBJECT_TYPE_COMMAND_POOL, pool, "commandPool");
        VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        VkFence fence;
        LC_VK(vkCreateFence(device_, &fci, nullptr, &fence));
        fence_ = FenceHandle(device_, fence);
        name(VK_OBJECT_TYPE_FENCE, fence, "submitFence");
    } catch (...) {
        release();
        throw;
    }
}

Context::~Context() { release(); }

void Context::release() {
    fence_.reset();
    commandPool_.reset();
    if (device_) vkDestroyDevice(device_, nullptr);
    device_ = VK_NULL_HANDLE;
    if (messenger_) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy) destroy(instance_, messenger_, nullptr);
    }
    messenger_ = VK_NULL_HANDLE;
    if (instance_) vkDestroyInstance(instance_, nullptr);
    instance_ = VK_NULL_HANDLE;
}

void Context::name(VkObjectType type, std::uint64_t handle, const std::string& n) const {
    if (!setName_ || !device_) return;
    std::string full = purpose_.empty() ? n : purpose_ + "." + n;
    VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
    info.objectType = type;
    info.objectHandle = handle;
    info.pObjectName = full.c_str();
    LC_VK(setName_(device_, &info));
}

void Context::beginLabel(VkCommandBuffer cmd, const char* label) const {
    if (!beginLabel_) return;
    VkDebugUtilsLabelEXT l{VK_STRUCTURE_TYPE_DEBUG_UTILS_LABEL_EXT};
    l.pLabelName = label;
    beginLabel_(cmd, &l);
}

void Context::endLabel(VkCommandBuffer cmd) const {
    if (endLabel_) endLabel_(cmd);
}

std::uint32_t Context::findMemoryType(std::uint32_t typeBits, VkMemoryPropertyFlags want) const {
    for (std::uint32_t i = 0; i < memProps_.memoryTypeCount; ++i)
        if ((typeBits & (1u << i)) && (memProps_.memoryTypes[i].propertyFlags & want) == want) return i;
    throw DeviceError("no Vulkan memory type with the required properties");
}

TrackedBytes::TrackedBytes(std::shared_ptr<MemoryStats> stats, std::uint64_t bytes)
    : stats_(std::move(stats)), bytes_(bytes) {
    stats_->live += bytes_;
    stats_->peak = std::max(stats_->peak, stats_->live);
    ++stats_->allocations;
}

TrackedBytes& TrackedBytes::operator=(TrackedBytes&& o) noexcept {
    if (this != &o) {
        release();
        stats_ = std::move(o.stats_);
        bytes_ = std::exchange(o.bytes_, 0);
    }
    return *this;
}

void TrackedBytes::release() {
    if (stats_) stats_->live -= bytes_;
    stats_.reset();
    bytes_ = 0;
}

bool Context::hasMemoryType(std::uint32_t typeBits, VkMemoryPropertyFlags want) const {
    for (std::uint32_t i = 0; i < memProps_.memoryTypeCount; ++i)
        if ((typeBits & (1u << i)) && (memProps_.memoryTypes[i].propertyFlags & want) == want) return true;
    return false;
}

Buffer Context::createBuffer(VkDeviceSize size, VkBufferUsageFlags usage, const std::string& n) const {
    return createBuffer(size, usage, n, Placement::Host);
}

Buffer Context::createReadbackBuffer(VkDeviceSize size, VkBufferUsageFlags usage,
                                     const std::string& n) const {
    return createBuffer(size, usage, n, Placement::HostRead);
}

Buffer Context::createDeviceBuffer(VkDeviceSize size, VkBufferUsageFlags usage, const std::string& n) const {
    return createBuffer(size, usage, n, Placement::Device);
}

Buffer Context::createBuffer(VkDeviceSize size, VkBufferUsageFlags usage, const std::string& n,
                             Placement where) const {
    // A device buffer moves through staging copies (createDeviceBuffer).
    if (where == Placement::Device) usage |= VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    Buffer b;
    b.size = std::max<VkDeviceSize>(size, 4);
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = b.size;
    bci.usage = usage;
    bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VkBuffer buf;
    LC_VK(vkCreateBuffer(device_, &bci, nullptr, &buf));
    b.buffer = BufferHandle(device_, buf);
    name(VK_OBJECT_TYPE_BUFFER, buf, n);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, buf, &req);
    const VkMemoryPropertyFlags hostFlags = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    VkMemoryPropertyFlags want = hostFlags;
    bool map = true;
    if (where == Placement::HostRead &&
        hasMemoryType(req.memoryTypeBits, hostFlags | VK_MEMORY_PROPERTY_HOST_CACHED_BIT))
        want = hostFlags | VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
    if (where == Placement::Device) {
        // A CPU device's memory is the host's: keep it mapped. A GPU's
        // device-local memory is never mapped (see createDeviceBuffer).
        const VkMemoryPropertyFlags both = hostFlags | VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
        map = isCpuDevice();
        if (!map) want = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
        else if (hasMemoryType(req.memoryTypeBits, both)) want = both;
    }
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = findMemoryType(req.memoryTypeBits, want);
    VkDeviceMemory mem;
    LC_VK(vkAllocateMemory(device_, &ai, nullptr, &mem));
    b.memory = MemoryHandle(device_, mem);
    b.tracked = TrackedBytes(memory_, req.size);
    name(VK_OBJECT_TYPE_DEVICE_MEMORY, mem, n + ".memory");
    LC_VK(vkBindBufferMemory(device_, buf, mem, 0));
    const VkMemoryPropertyFlags got = memProps_.memoryTypes[ai.memoryTypeIndex].propertyFlags;
    if (map && (got & hostFlags) == hostFlags) LC_VK(vkMapMemory(device_, mem, 0, VK_WHOLE_SIZE, 0, &b.mapped));
    return b;
}

BufferCache::Frame::Frame(BufferCache& cache) : cache_(cache) {
    if (cache_.inFrame_) throw std::logic_error("BufferCache: a frame opened inside another");
    cache_.inFrame_ = true;
}

BufferCache::Frame::~Frame() {
    cache_.inFrame_ = false;
    cache_.taken_.clear();
}

const Buffer& BufferCache::get(const std::string& role, VkDeviceSize bytes, VkBufferUsageFlags usage,
                               Kind kind) {
    if (!inFrame_) throw std::logic_error("BufferCache: buffer role '" + role + "' asked for outside a frame");
    if (!taken_.insert(role).second)
        throw std::logic_error("BufferCache: buffer role '" + role +
                               "' asked for twice in one frame (the first reference would dangle)");
    bytes = std::max<VkDeviceSize>(bytes, 4);
    auto it = entries_.find(role);
    if (it != entries_.end()) {
        const Entry& e = it->second;
        if (e.kind == kind && e.usage == usage && e.buffer.size >= bytes && e.buffer.size / 4 <= bytes)
            return e.buffer;
        entries_.erase(it); // freed before its successor is made
    }
    const VkDeviceSize size = bytes + bytes / 4;
    Entry e;
    e.usage = usage;
    e.kind = kind;
    e.buffer = ctx_.createBuffer(size, usage, role, kind);
    return entries_.emplace(role, std::move(e)).first->second.buffer;
}

TimestampPool::TimestampPool(const Context& ctx, std::uint32_t spans, const std::string& n)
    : device_(ctx.device()), spans_(spans) {
    VkQueryPoolCreateInfo ci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    ci.queryType = VK_QUERY_TYPE_TIMESTAMP;
    ci.queryCount = 2 * spans;
    VkQueryPool qp;
    LC_VK(vkCreateQueryPool(device_, &ci, nullptr, &qp));
    pool_ = QueryPoolHandle(device_, qp);
    ctx.name(VK_OBJECT_TYPE_QUERY_POOL, qp, n);
    nsPerTick_ = ctx.properties().limits.timestampPeriod;
    const std::uint32_t bits = ctx.timestampValidBits();
    validMask_ = bits >= 64 ? ~0ull : ((1ull << bits) - 1);
}

void TimestampPool::reset(VkCommandBuffer cmd) const { vkCmdResetQueryPool(cmd, pool_, 0, 2 * spans_); }

// Both ends at bottom of pipe: written once every earlier command of the
// queue has completed, so a span starts after the uploads recorded before it
// and ends after the last pass inside it.
void TimestampPool::begin(VkCommandBuffer cmd, std::uint32_t span) const {
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, 2 * span);
}

void TimestampPool::end(VkCommandBuffer cmd, std::uint32_t span) const {
    vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, 2 * span + 1);
}

double TimestampPool::milliseconds(std::uint32_t span) const {
    std::uint64_t t[2] = {0, 0};
    LC_VK(vkGetQueryPoolResults(device_, pool_, 2 * span, 2, sizeof(t), t, sizeof(std::uint64_t),
                                VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
    const std::uint64_t ticks = ((t[1] & validMask_) - (t[0] & validMask_)) & validMask_;
    return double(ticks) * nsPerTick_ * 1e-6;
}

Image Context::createDepthImage(std::uint32_t w, std::uint32_t h, VkFormat format, const std::string& n) const {
    return createImage(w, h, format, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                       VK_IMAGE_ASPECT_DEPTH_BIT, n);
}

Image Context::createImage(std::uint32_t w, std::uint32_t h, VkFormat format, VkImageUsageFlags usage,
                           VkImageAspectFlags aspect, const std::string& n) const {
    Image img;
    VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = format;
    ici.extent = {w, h, 1};
    ici.mipLevels = 1;
    ici.arrayLayers = 1;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = usage;
    ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    VkImage im;
    LC_VK(vkCreateImage(device_, &ici, nullptr, &im));
    img.image = ImageHandle(device_, im);
    name(VK_OBJECT_TYPE_IMAGE, im, n);
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device_, im, &req);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VkDeviceMemory mem;
    LC_VK(vkAllocateMemory(device_, &ai, nullptr, &mem));
    img.memory = MemoryHandle(device_, mem);
    img.tracked = TrackedBytes(memory_, req.size);
    name(VK_OBJECT_TYPE_DEVICE_MEMORY, mem, n + ".memory");
    LC_VK(vkBindImageMemory(device_, im, mem, 0));
    VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vci.image = im;
    vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vci.format = format;
    vci.subresourceRange = {aspect, 0, 1, 0, 1};
    VkImageView view;
    LC_VK(vkCreateImageView(device_, &vci, nullptr, &view));
    img.view = ImageViewHandle(device_, view);
    name(VK_OBJECT_TYPE_IMAGE_VIEW, view, n + ".view");
    return img;
}

ShaderModuleHandle Context::createShader(const std::uint32_t* words, std::size_t wordCount,
                                         const std::string& n) const {
    VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    ci.codeSize = wordCount * 4;
    ci.pCode = words;
    VkShaderModule m;
    LC_VK(vkCreateShaderModule(device_, &ci, nullptr, &m));
    name(VK_OBJECT_TYPE_SHADER_MODULE, m, n);
    return ShaderModuleHandle(device_, m);
}

Context::PassLayouts Context::createPassLayouts(const std::vector<VkDescriptorType>& types, const std::string& n,
                                                std::uint32_t pushConstantBytes, VkShaderStageFlags stages) const {
    std::vector<VkDescriptorSetLayoutBinding> b(types.size());
    for (std::uint32_t i = 0; i < types.size(); ++i) {
        b[i].binding = i;
        b[i].descriptorType = types[i];
        b[i].descriptorCount = 1;
        b[i].stageFlags = stages;
    }
    VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    lci.bindingCount = std::uint32_t(b.size());
    lci.pBindings = b.data();
    VkDescriptorSetLayout sl;
    LC_VK(vkCreateDescriptorSetLayout(device_, &lci, nullptr, &sl));
    PassLayouts out;
    out.set = DescriptorSetLayoutHandle(device_, sl);
    name(VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, sl, n + ".setLayout");
    const VkPushConstantRange push{stages, 0, pushConstantBytes};
    VkPipelineLayoutCreateInfo pci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pci.setLayoutCount = 1;
    pci.pSetLayouts = &sl;
    pci.pushConstantRangeCount = pushConstantBytes ? 1 : 0;
    pci.pPushConstantRanges = &push;
    VkPipelineLayout pl;
    LC_VK(vkCreatePipelineLayout(device_, &pci, nullptr, &pl));
    out.pipeline = PipelineLayoutHandle(device_, pl);
    name(VK_OBJECT_TYPE_PIPELINE_LAYOUT, pl, n + ".pipelineLayout");
    return out;
}

DescriptorPoolHandle Context::createDescriptorPool(const std::vector<DescriptorWrite>& bindings,
                                                  std::uint32_t sets, const std::string& n) const {
    std::map<VkDescriptorType, std::uint32_t> perType;
    for (const DescriptorWrite& b : bindings) perType[b.type] += sets;
    std::vector<VkDescriptorPoolSize> sizes;
    for (const auto& [type, count] : perType) sizes.push_back({type, count});
    VkDescriptorPoolCreateInfo ci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    ci.maxSets = sets;
    ci.poolSizeCount = std::uint32_t(sizes.size());
    ci.pPoolSizes = sizes.data();
    VkDescriptorPool pool;
    LC_VK(vkCreateDescriptorPool(device_, &ci, nullptr, &pool));
    name(VK_OBJECT_TYPE_DESCRIPTOR_POOL, pool, n);
    return DescriptorPoolHandle(device_, pool);
}

VkDescriptorSet Context::writeDescriptorSet(VkDescriptorPool pool, VkDescriptorSetLayout layout,
                                            const std::vector<DescriptorWrite>& bindings,
                                            const std::string& n) const {
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = pool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &layout;
    VkDescriptorSet set;
    LC_VK(vkAllocateDescriptorSets(device_, &ai, &set));
    name(VK_OBJECT_TYPE_DESCRIPTOR_SET, set, n);
    std::vector<VkDescriptorBufferInfo> infos(bindings.size());
    std::vector<VkWriteDescriptorSet> writes(bindings.size());
    for (std::uint32_t i = 0; i < bindings.size(); ++i) {
        const DescriptorWrite& b = bindings[i];
        writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        writes[i].dstSet = set;
        writes[i].dstBinding = i;
        writes[i].descriptorCount = 1;
        writes[i].descriptorType = b.type;
        if (b.type == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER || b.type == VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE ||
            b.type == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE) {
            writes[i].pImageInfo = &b.image;
        } else {
            infos[i] = {b.buffer, 0, b.range};
            writes[i].pBufferInfo = &infos[i];
        }
    }
    vkUpdateDescriptorSets(device_, std::uint32_t(writes.size()), writes.data(), 0, nullptr);
    return set;
}

namespace {
constexpr double kSpinMs = 2.0;
} // namespace

bool Context::submitAndWaitFor(const std::function<void(VkCommandBuffer)>& record, const std::string& n,
                               double timeoutMs, double& wallMs) {
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = commandPool_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VkCommandBuffer cmd;
    LC_VK(vkAllocateCommandBuffers(device_, &ai, &cmd));
    // Freed on every exit path (the pool owns it; this returns it early),
    // except after a timeout: the device may still be executing it.
    struct FreeCmd {
        VkDevice d;
        VkCommandPool p;
        VkCommandBuffer c;
        bool keep = false;
        ~FreeCmd() {
            if (!keep) vkFreeCommandBuffers(d, p, 1, &c);
        }
    } freeCmd{device_, commandPool_, cmd};
    name(VK_OBJECT_TYPE_COMMAND_BUFFER, cmd, n);
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    LC_VK(vkBeginCommandBuffer(cmd, &bi));
    {
        // One marker region per submission, named as its command buffer.
        const std::string label = purpose_.empty() ? n : purpose_ + "." + n;
        LabelScope region(*this, cmd, label.c_str());
        record(cmd);
    }
    LC_VK(vkEndCommandBuffer(cmd));
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    VkFence f = fence_;
    LC_VK(vkResetFences(device_, 1, &f));
    // No limit (submitAndWait) or a finite one in nanoseconds.
    const std::uint64_t timeoutNs = std::isfinite(timeoutMs) && timeoutMs > 0
                                        ? std::uint64_t(std::min(timeoutMs, 1e9) * 1e6)
                                        : UINT64_MAX;
    const auto t0 = std::chrono::steady_clock::now();
    LC_VK(vkQueueSubmit(queue_, 1, &si, f));
    // On a GPU, poll the fence for up to kSpinMs before sleeping in the
    // driver: the short submissions of a cull end within that, and a
    // vkWaitForFences wake-up took about 85 us on the H100 (P1's wall clock
    // 0.20 against 0.12 ms polled). Not on a CPU device, whose driver needs
    // the cores the poll would take.
    VkResult r = VK_NOT_READY;
    if (!isCpuDevice()) {
        const auto spinUntil = t0 + std::chrono::duration<double, std::milli>(std::min(kSpinMs, timeoutMs));
        while ((r = vkGetFenceStatus(device_, f)) == VK_NOT_READY && std::chrono::steady_clock::now() < spinUntil) {
        }
        if (r != VK_SUCCESS && r != VK_NOT_READY) throwVkError("vkGetFenceStatus", r, __FILE__, __LINE__);
    }
    if (r == VK_NOT_READY) r = vkWaitForFences(device_, 1, &f, VK_TRUE, timeoutNs);
    wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (r == VK_TIMEOUT) {
        freeCmd.keep = true; // still pending: left to the context the caller abandons
        return false;
    }
    if (r != VK_SUCCESS) throwVkError("vkWaitForFences", r, __FILE__, __LINE__);
    return true;
}

double Context::submitAndWait(const std::function<void(VkCommandBuffer)>& record, const std::string& n) {
    double wallMs = 0;
    submitAndWaitFor(record, n, std::numeric_limits<double>::infinity(), wallMs); // never times out
    return wallMs;
}

} // namespace lc::vk

namespace lc {
bool vulkanInstanceCreated() { return vk::g_instanceCreated; }
std::uint64_t vulkanInstancesOpened() { return vk::g_instancesOpened; }
} // namespace lc
