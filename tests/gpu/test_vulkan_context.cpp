// The Vulkan context: the validation layer really loads (and catches a
// deliberately invalid call), device choice by index / name / environment,
// and typed errors naming the failed call, its result and the source line.
#include "gpu_test_env.hpp"

#include "../unit/cli_support.hpp"

#include "culling/core/errors.hpp"
#include "vk/vk_context.hpp"

#include <algorithm>
#include <cctype>

using namespace lc;
using lc::gputest::GpuTest;

namespace {

TEST_F(GpuTest, ValidationLayerAndSyncValidationAreEnabled) {
    CullBackend& b = gputest::vulkan();
    EXPECT_EQ(b.name(), "vulkan");
    EXPECT_FALSE(b.deviceName().empty());
    EXPECT_TRUE(vk::validationRequested());
    EXPECT_TRUE(vk::validationLayerActive()) << "VK_LAYER_KHRONOS_validation was not enabled";
    EXPECT_TRUE(vk::syncValidationActive()) << "synchronisation validation was not enabled";
    std::printf("[ vulkan   ] device: %s, timing: %s\n", b.deviceName().c_str(), b.timingMethod().c_str());
}

// A buffer of size 0 violates VUID-VkBufferCreateInfo-size-00912: the layer
// must report it through our messenger (proving messages reach the tests).
TEST_F(GpuTest, LayerReportsADeliberatelyInvalidCall) {
    vk::Context ctx(vk::ContextOptions{"", "lc.test"});
    vk::clearValidationMessages();
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = 0; // invalid on purpose
    bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VkBuffer buf = VK_NULL_HANDLE;
    VkResult r = vkCreateBuffer(ctx.device(), &bci, nullptr, &buf);
    if (r == VK_SUCCESS && buf) vkDestroyBuffer(ctx.device(), buf, nullptr);
    auto msgs = vk::validationMessages();
    const bool found = std::any_of(msgs.begin(), msgs.end(), [](const std::string& m) {
        return m.find("VUID-VkBufferCreateInfo-size-00912") != std::string::npos;
    });
    EXPECT_TRUE(found) << "the layer did not report the invalid call; got:\n" << gputest::joinedMessages();
    vk::clearValidationMessages(); // the expected message must not fail TearDown
}

VkResult failingCall() { return VK_ERROR_OUT_OF_DEVICE_MEMORY; }

TEST_F(GpuTest, FailedCallThrowsDeviceErrorWithCallResultFileAndLine) {
    try {
        LC_VK(failingCall());
        FAIL() << "no throw";
    } catch (const DeviceError& e) {
        const std::string w = e.what();
        EXPECT_NE(w.find("failingCall()"), std::string::npos) << w;
        EXPECT_NE(w.find("VK_ERROR_OUT_OF_DEVICE_MEMORY"), std::string::npos) << w;
        EXPECT_NE(w.find("test_vulkan_context.cpp:"), std::string::npos) << w;
    }
}

TEST_F(GpuTest, DeviceChoiceByIndexNameAndEnvironment) {
    const auto names = vulkanDeviceNames();
    ASSERT_FALSE(names.empty());
    // By index.
    EXPECT_EQ(makeVulkanBackend("0")->deviceName(), names[0]);
    EXPECT_THROW(makeVulkanBackend(std::to_string(names.size() + 7)), DeviceError);
    // By case-insensitive name substring: the middle of device 0's name, upper-cased.
    std::string sub = names[0].substr(0, std::min<std::size_t>(names[0].size(), 6));
    std::transform(sub.begin(), sub.end(), sub.begin(), [](unsigned char c) { return char(std::toupper(c)); });
    EXPECT_EQ(makeVulkanBackend(sub)->deviceName(), names[0]); // first match wins
    try {
        makeVulkanBackend("no-such-gpu-xyz");
        FAIL() << "no throw";
    } catch (const DeviceError& e) {
        EXPECT_NE(std::string(e.what()).find("no-such-gpu-xyz"), std::string::npos) << e.what();
    }
    // LIGHTCULL_DEVICE applies when the argument is empty; the argument wins.
    setenv("LIGHTCULL_DEVICE", "no-such-gpu-xyz", 1);
    EXPECT_THROW(makeVulkanBackend(""), DeviceError);
    EXPECT_NO_THROW(makeVulkanBackend("0"));
    unsetenv("LIGHTCULL_DEVICE");
    // Through the public registry too.
    EXPECT_EQ(makeBackend("vulkan", "0")->name(), "vulkan");
    const auto avail = availableBackends();
    EXPECT_NE(std::find(avail.begin(), avail.end(), "vulkan"), avail.end());
}

// The CLI's default backend falls back to the CPU when no Vulkan device
// opens, but a device the user named is wanted: naming one that is not there
// fails, rather than timing the CPU under the name asked for.
TEST_F(GpuTest, ANamedDeviceThatIsNotThereIsAnErrorNotTheCpu) {
    lc_test::ScratchDir d;
    const lc_test::CliResult r = lc_test::runCli({"run", "--builtin", "atrium", "--width", "64", "--height", "64",
                                                  "--device", "no-such-gpu-xyz", "--out", (d.path / "o").string()},
                                                 d.path);
    EXPECT_EQ(r.code, 1) << r.out << r.err;
    EXPECT_NE(r.err.find("no Vulkan device matches 'no-such-gpu-xyz'"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    const lc_test::CliResult ok = lc_test::runCli(
        {"run", "--builtin", "atrium", "--width", "64", "--height", "64", "--device", "0", "--out", (d.path / "p").string()},
        d.path);
    EXPECT_EQ(ok.code, 0) << ok.err;
    EXPECT_NE(ok.out.find("backend vulkan"), std::string::npos) << ok.out;
}

} // namespace

namespace {

// No driver at all (the loader pointed at a missing ICD file): a DeviceError
// with a clear message, no crash, and no device names, so callers can fall
// back to the CPU backend.
TEST_F(GpuTest, NoDriverIsAClearDeviceError) {
    ASSERT_TRUE(vk::validationMessages().empty()) << gputest::joinedMessages();
    setenv("VK_ICD_FILENAMES", "/nonexistent/lightcull_no_icd.json", 1);
    setenv("VK_DRIVER_FILES", "/nonexistent/lightcull_no_icd.json", 1);
    EXPECT_TRUE(vulkanDeviceNames().empty());
    try {
        makeVulkanBackend("");
        ADD_FAILURE() << "no throw without a driver";
    } catch (const DeviceError& e) {
        const std::string w = e.what();
        EXPECT_TRUE(w.find("no Vulkan driver") != std::string::npos ||
                    w.find("no Vulkan device") != std::string::npos)
            << w;
    }
    unsetenv("VK_ICD_FILENAMES");
    unsetenv("VK_DRIVER_FILES");
    EXPECT_FALSE(vulkanDeviceNames().empty());
    // The loader itself may warn about the missing ICD file; that is the point
    // of this test, not a validation finding.
    vk::clearValidationMessages();
}

} // namespace

// A role asked for twice in one frame would hand back a reference to a buffer
// the second ask may have replaced: the cache refuses instead, and refuses
// any ask outside a frame. A new frame may ask for the role again, and the
// buffer it kept (large enough) is the same one.
TEST_F(GpuTest, BufferCacheRolesAreAskedForOncePerFrame) {
    vk::Context ctx(vk::ContextOptions{"", "lc.test"});
    vk::BufferCache cache(ctx);
    const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    EXPECT_THROW(cache.get("a", 64, usage, vk::BufferCache::Kind::Host), std::logic_error);
    VkBuffer first = VK_NULL_HANDLE;
    {
        vk::BufferCache::Frame frame(cache);
        first = cache.get("a", 64, usage, vk::BufferCache::Kind::Host).buffer;
        EXPECT_NO_THROW(cache.get("b", 64, usage, vk::BufferCache::Kind::Host));
        try {
            cache.get("a", 4096, usage, vk::BufferCache::Kind::Host);
            FAIL() << "a role asked for twice in one frame";
        } catch (const std::logic_error& e) {
            EXPECT_NE(std::string(e.what()).find("'a' asked for twice"), std::string::npos) << e.what();
        }
        EXPECT_THROW(vk::BufferCache::Frame nested(cache), std::logic_error);
    }
    vk::BufferCache::Frame next(cache);
    EXPECT_EQ(cache.get("a", 60, usage, vk::BufferCache::Kind::Host).buffer, first) << "kept between frames";
}
