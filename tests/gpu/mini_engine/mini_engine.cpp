// A minimal renderer that is not lightcull: it draws a floor and a few boxes
// into a depth attachment, culls its 64 lights into tiles with its own
// compute shader (cull.comp: its own light struct in world space, row-major
// frame constants, lists as per-tile counts plus fixed-stride indices) and
// captures that frame through RenderDoc's in-application API, as an engine
// would. tests/gpu/test_renderdoc.cpp then judges the capture with `lightcull
// check --capture` and a description of this program's layout, knowing
// nothing of this code.
//
//   gpu_mini_engine CAPTURE.rdc LISTS.csv [--reversed] [--bug]
//
// LISTS.csv gets the lists the program read back (list,light,...), for the
// test to compare. LIGHTCULL_VALIDATION=1 turns on the Khronos validation
// layer; any message fails the program (exit 1).
#include <renderdoc_app.h>

#include <vulkan/vulkan.h>

#define GLM_FORCE_DEPTH_ZERO_TO_ONE
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <dlfcn.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "mini_engine_cull.spv.h"
#include "mini_engine_depth.spv.h"

namespace {

constexpr std::uint32_t kWidth = 250, kHeight = 140, kTile = 16, kMaxLights = 32, kLights = 64;
int g_messages = 0;

#define CHECK(x)                                                                                                    \
    do {                                                                                                            \
        const VkResult r_ = (x);                                                                                    \
        if (r_ != VK_SUCCESS) {                                                                                     \
            std::fprintf(stderr, "mini_engine: %s failed (%d) at line %d\n", #x, int(r_), __LINE__);                \
            std::exit(1);                                                                                           \
        }                                                                                                           \
    } while (0)

VKAPI_ATTR VkBool32 VKAPI_CALL onMessage(VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT,
                                         const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
    std::fprintf(stderr, "mini_engine: validation: %s\n", data->pMessage);
    ++g_messages;
    return VK_FALSE;
}

struct EngineLight { // as cull.comp declares it (std430, 32 bytes)
    glm::vec4 color;
    glm::vec3 positionWS;
    float range;
};

struct Gpu {
    VkInstance instance = VK_NULL_HANDLE;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    std::uint32_t family = 0;
    VkPhysicalDeviceMemoryProperties memory{};
    PFN_vkSetDebugUtilsObjectNameEXT setName = nullptr;
    PFN_vkCmdBeginDebugUtilsLabelEXT beginLabel = nullptr;
    PFN_vkCmdEndDebugUtilsLabelEXT endLabel = nullptr;

    void name(VkObjectType type, std::uint64_t handle, const char* n) const {
        if (!setName) return;
        VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
        info.objectType = type;
        info.objectHandle = handle;
        info.pObjectName = n;
        setName(device, &info);
    }
    std::uint32_t memoryType(std::uint32_t bits, VkMemoryPropertyFlags want) const {
        for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i)
            if ((bits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & want) == want) return i;
        std::fprintf(stderr, "mini_engine: no suitable memory type\n");
        std::exit(1);
    }
};

struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
};

Buffer makeBuffer(const Gpu& g, VkDeviceSize size, VkBufferUsageFlags usage, const char* name) {
    Buffer b;
    VkBufferCreateInfo ci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    ci.size = size;
    ci.usage = usage;
    CHECK(vkCreateBuffer(g.device, &ci, nullptr, &b.buffer));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(g.device, b.buffer, &req);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex =
        g.memoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    CHECK(vkAllocateMemory(g.device, &ai, nullptr, &b.memory));
    CHECK(vkBindBufferMemory(g.device, b.buffer, b.memory, 0));
    CHECK(vkMapMemory(g.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped));
    std::memset(b.mapped, 0, size);
    g.name(VK_OBJECT_TYPE_BUFFER, reinterpret_cast<std::uint64_t>(b.buffer), name);
    return b;
}

VkShaderModule makeShader(const Gpu& g, const std::uint32_t* words, std::size_t bytes) {
    VkShaderModuleCreateInfo ci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    ci.codeSize = bytes;
    ci.pCode = words;
    VkShaderModule m;
    CHECK(vkCreateShaderModule(g.device, &ci, nullptr, &m));
    return m;
}

Gpu openGpu(bool validation) {
    Gpu g;
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "mini engine";
    app.apiVersion = VK_API_VERSION_1_1;
    const char* layer = "VK_LAYER_KHRONOS_validation";
    const char* ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                      VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    mci.pfnUserCallback = onMessage;
    VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ci.pApplicationInfo = &app;
    ci.enabledExtensionCount = 1;
    ci.ppEnabledExtensionNames = &ext;
    if (validation) {
        ci.enabledLayerCount = 1;
        ci.ppEnabledLayerNames = &layer;
        ci.pNext = &mci;
    }
    CHECK(vkCreateInstance(&ci, nullptr, &g.instance));
    if (validation) {
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(g.instance, "vkCreateDebugUtilsMessengerEXT"));
        VkDebugUtilsMessengerEXT messenger;
        CHECK(create(g.instance, &mci, nullptr, &messenger));
    }
    std::uint32_t n = 1;
    const VkResult r = vkEnumeratePhysicalDevices(g.instance, &n, &g.physical);
    if ((r != VK_SUCCESS && r != VK_INCOMPLETE) || n == 0) {
        std::fprintf(stderr, "mini_engine: no Vulkan device\n");
        std::exit(1);
    }
    vkGetPhysicalDeviceMemoryProperties(g.physical, &g.memory);
    std::uint32_t qn = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(g.physical, &qn, nullptr);
    std::vector<VkQueueFamilyProperties> qs(qn);
    vkGetPhysicalDeviceQueueFamilyProperties(g.physical, &qn, qs.data());
    for (g.family = 0; g.family < qn; ++g.family)
        if ((qs[g.family].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) ==
            (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT))
            break;
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = g.family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    CHECK(vkCreateDevice(g.physical, &dci, nullptr, &g.device));
    vkGetDeviceQueue(g.device, g.family, 0, &g.queue);
    g.setName = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
        vkGetInstanceProcAddr(g.instance, "vkSetDebugUtilsObjectNameEXT"));
    g.beginLabel = reinterpret_cast<PFN_vkCmdBeginDebugUtilsLabelEXT>(
        vkGetInstanceProcAddr(g.instance, "vkCmdBeginDebugUtilsLabelEXT"));
    g.endLabel = reinterpret_cast<PFN_vkCmdEndDebugUtilsLabelEXT>(
        vkGetInstanceProcAddr(g.instance, "vkCmdEndDebugUtilsLabelEXT"));
    return g;
}

// A floor and three boxes, world space, as triangles.
std::vector<glm::vec3> sceneTriangles() {
    std::vector<glm::vec3> v;
    const auto quad = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
        v.insert(v.end(), {a, b, c, a, c, d});
    };
    quad({-40, 0, 20}, {40, 0, 20}, {40, 0, -60}, {-40, 0, -60});
    const auto box = [&](glm::vec3 lo, glm::vec3 hi) {
        quad({lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}); // front
        quad({hi.x, lo.y, lo.z}, {lo.x, lo.y, lo.z}, {lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z}); // back
        quad({lo.x, lo.y, lo.z}, {lo.x, lo.y, hi.z}, {lo.x, hi.y, hi.z}, {lo.x, hi.y, lo.z}); // left
        quad({hi.x, lo.y, hi.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}); // right
        quad({lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z}); // top
    };
    box({-6, 0, -14}, {-2, 5, -10});
    box({3, 0, -22}, {8, 9, -16});
    box({-1, 0, -6}, {1, 2, -4});
    return v;
}

std::vector<EngineLight> sceneLights() {
    std::vector<EngineLight> lights(kLights);
    std::uint32_t s = 12345;
    const auto next = [&] {
        s = s * 1664525u + 1013904223u;
        return float(s >> 8) / float(1u << 24);
    };
    for (EngineLight& l : lights) {
        l.color = glm::vec4(next(), next(), next(), 1.0f);
        l.positionWS = glm::vec3(-15.0f + 30.0f * next(), 0.2f + 6.0f * next(), 2.0f - 40.0f * next());
        l.range = 1.0f + 3.0f * next();
    }
    return lights;
}

void store(float* out, const glm::mat4& m) { // row-major, as the shaders declare
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) out[r * 4 + c] = m[c][r];
}

} // namespace

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: gpu_mini_engine CAPTURE.rdc LISTS.csv [--reversed] [--bug]\n");
        return 2;
    }
    bool reversed = false, bug = false;
    for (int i = 3; i < argc; ++i) {
        reversed |= std::strcmp(argv[i], "--reversed") == 0;
        bug |= std::strcmp(argv[i], "--bug") == 0;
    }
    const char* v = std::getenv("LIGHTCULL_VALIDATION");
    const bool validation = v && std::strcmp(v, "1") == 0;

    // RenderDoc first, before any Vulkan instance (its layer is picked then).
    setenv("ENABLE_VULKAN_RENDERDOC_CAPTURE", "1", 1);
    void* rdLib = dlopen("librenderdoc.so", RTLD_NOW | RTLD_GLOBAL);
    RENDERDOC_API_1_6_0* rdoc = nullptr;
    if (rdLib) {
        auto getApi = reinterpret_cast<pRENDERDOC_GetAPI>(dlsym(rdLib, "RENDERDOC_GetAPI"));
        if (getApi) getApi(eRENDERDOC_API_Version_1_6_0, reinterpret_cast<void**>(&rdoc));
    }
    if (!rdoc) {
        std::fprintf(stderr, "mini_engine: cannot load RenderDoc (apt-get install librenderdoc)\n");
        return 1;
    }
    const std::filesystem::path capturePath = std::filesystem::absolute(argv[1]);
    const std::filesystem::path captureDir = capturePath.parent_path() / "mini_engine_capture";
    std::filesystem::create_directories(captureDir);
    rdoc->SetCaptureFilePathTemplate((captureDir / "frame").c_str());

    Gpu g = openGpu(validation);
    const VkFormat depthFormat = VK_FORMAT_D32_SFLOAT;

    // Frame constants.
    const glm::mat4 view = glm::lookAt(glm::vec3(0, 4, 8), glm::vec3(0, 2, -20), glm::vec3(0, 1, 0));
    glm::mat4 proj = reversed ? glm::perspectiveRH_ZO(glm::radians(55.0f), float(kWidth) / kHeight, 200.0f, 0.3f)
                              : glm::perspectiveRH_ZO(glm::radians(55.0f), float(kWidth) / kHeight, 0.3f, 200.0f);
    proj[1][1] *= -1.0f; // Vulkan: y down
    Buffer constants = makeBuffer(g, 144, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, "FrameConstants");
    auto* cf = static_cast<float*>(constants.mapped);
    store(cf, view);
    store(cf + 16, proj);
    auto* cu = reinterpret_cast<std::uint32_t*>(cf + 32);
    cu[0] = kWidth, cu[1] = kHeight, cu[2] = kTile, cu[3] = kLights;

    const std::vector<EngineLight> lights = sceneLights();
    Buffer lightBuf = makeBuffer(g, sizeof(EngineLight) * lights.size(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "LightBuffer");
    std::memcpy(lightBuf.mapped, lights.data(), sizeof(EngineLight) * lights.size());
    const std::vector<glm::vec3> tris = sceneTriangles();
    Buffer vertices = makeBuffer(g, sizeof(glm::vec3) * tris.size(), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, "SceneVertices");
    std::memcpy(vertices.mapped, tris.data(), sizeof(glm::vec3) * tris.size());
    const std::uint32_t tilesX = (kWidth + kTile - 1) / kTile, tilesY = (kHeight + kTile - 1) / kTile;
    const std::uint32_t tiles = tilesX * tilesY;
    Buffer counts = makeBuffer(g, 4 * tiles, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "TileLightCounts");
    Buffer indices = makeBuffer(g, 4 * tiles * kMaxLights, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "TileLightIndices");

    // The depth attachment, sampled by the culling.
    VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = depthFormat;
    ici.extent = {kWidth, kHeight, 1};
    ici.mipLevels = 1;
    ici.arrayLayers = 1;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    VkImage depth;
    CHECK(vkCreateImage(g.device, &ici, nullptr, &depth));
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(g.device, depth, &req);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = g.memoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VkDeviceMemory depthMemory;
    CHECK(vkAllocateMemory(g.device, &ai, nullptr, &depthMemory));
    CHECK(vkBindImageMemory(g.device, depth, depthMemory, 0));
    g.name(VK_OBJECT_TYPE_IMAGE, reinterpret_cast<std::uint64_t>(depth), "SceneDepth");
    VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vci.image = depth;
    vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vci.format = depthFormat;
    vci.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
    VkImageView depthView;
    CHECK(vkCreateImageView(g.device, &vci, nullptr, &depthView));
    VkSamplerCreateInfo sci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    VkSampler sampler;
    CHECK(vkCreateSampler(g.device, &sci, nullptr, &sampler));

    // Depth pre-pass: render pass, pipeline.
    VkAttachmentDescription att{};
    att.format = depthFormat;
    att.samples = VK_SAMPLE_COUNT_1_BIT;
    att.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    att.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    att.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    att.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    att.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    att.finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL;
    VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.pDepthStencilAttachment = &ref;
    VkSubpassDependency dep{};
    dep.srcSubpass = 0;
    dep.dstSubpass = VK_SUBPASS_EXTERNAL;
    dep.srcStageMask = VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    dep.srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    dep.dstStageMask = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
    dep.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    VkRenderPassCreateInfo rci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    rci.attachmentCount = 1;
    rci.pAttachments = &att;
    rci.subpassCount = 1;
    rci.pSubpasses = &sub;
    rci.dependencyCount = 1;
    rci.pDependencies = &dep;
    VkRenderPass renderPass;
    CHECK(vkCreateRenderPass(g.device, &rci, nullptr, &renderPass));
    VkFramebufferCreateInfo fci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fci.renderPass = renderPass;
    fci.attachmentCount = 1;
    fci.pAttachments = &depthView;
    fci.width = kWidth;
    fci.height = kHeight;
    fci.layers = 1;
    VkFramebuffer framebuffer;
    CHECK(vkCreateFramebuffer(g.device, &fci, nullptr, &framebuffer));

    // One descriptor set for both passes.
    const VkDescriptorType types[5] = {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                       VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                       VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
    VkDescriptorSetLayoutBinding lb[5]{};
    for (std::uint32_t i = 0; i < 5; ++i) {
        lb[i].binding = i;
        lb[i].descriptorType = types[i];
        lb[i].descriptorCount = 1;
        lb[i].stageFlags = i == 0 ? VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_COMPUTE_BIT : VK_SHADER_STAGE_COMPUTE_BIT;
    }
    VkDescriptorSetLayoutCreateInfo dlci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dlci.bindingCount = 5;
    dlci.pBindings = lb;
    VkDescriptorSetLayout setLayout;
    CHECK(vkCreateDescriptorSetLayout(g.device, &dlci, nullptr, &setLayout));
    VkPipelineLayoutCreateInfo plci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    plci.setLayoutCount = 1;
    plci.pSetLayouts = &setLayout;
    VkPipelineLayout pipelineLayout;
    CHECK(vkCreatePipelineLayout(g.device, &plci, nullptr, &pipelineLayout));
    VkDescriptorPoolSize sizes[3] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1},
                                     {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 3},
                                     {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1}};
    VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dpci.maxSets = 1;
    dpci.poolSizeCount = 3;
    dpci.pPoolSizes = sizes;
    VkDescriptorPool pool;
    CHECK(vkCreateDescriptorPool(g.device, &dpci, nullptr, &pool));
    VkDescriptorSetAllocateInfo dsai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    dsai.descriptorPool = pool;
    dsai.descriptorSetCount = 1;
    dsai.pSetLayouts = &setLayout;
    VkDescriptorSet set;
    CHECK(vkAllocateDescriptorSets(g.device, &dsai, &set));
    VkDescriptorBufferInfo bufInfo[5] = {{constants.buffer, 0, VK_WHOLE_SIZE},
                                         {lightBuf.buffer, 0, VK_WHOLE_SIZE},
                                         {},
                                         {counts.buffer, 0, VK_WHOLE_SIZE},
                                         {indices.buffer, 0, VK_WHOLE_SIZE}};
    VkDescriptorImageInfo imgInfo{sampler, depthView, VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL};
    VkWriteDescriptorSet writes[5]{};
    for (std::uint32_t i = 0; i < 5; ++i) {
        writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        writes[i].dstSet = set;
        writes[i].dstBinding = i;
        writes[i].descriptorCount = 1;
        writes[i].descriptorType = types[i];
        if (i == 2)
            writes[i].pImageInfo = &imgInfo;
        else
            writes[i].pBufferInfo = &bufInfo[i];
    }
    vkUpdateDescriptorSets(g.device, 5, writes, 0, nullptr);

    VkShaderModule vs = makeShader(g, mini_engine_depth, sizeof mini_engine_depth);
    VkShaderModule cs = makeShader(g, mini_engine_cull, sizeof mini_engine_cull);
    VkPipelineShaderStageCreateInfo vstage{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    vstage.stage = VK_SHADER_STAGE_VERTEX_BIT;
    vstage.module = vs;
    vstage.pName = "main";
    VkVertexInputBindingDescription vb{0, sizeof(glm::vec3), VK_VERTEX_INPUT_RATE_VERTEX};
    VkVertexInputAttributeDescription va{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0};
    VkPipelineVertexInputStateCreateInfo vin{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    vin.vertexBindingDescriptionCount = 1;
    vin.pVertexBindingDescriptions = &vb;
    vin.vertexAttributeDescriptionCount = 1;
    vin.pVertexAttributeDescriptions = &va;
    VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkViewport viewport{0, 0, float(kWidth), float(kHeight), 0, 1};
    VkRect2D scissor{{0, 0}, {kWidth, kHeight}};
    VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    vp.viewportCount = 1;
    vp.pViewports = &viewport;
    vp.scissorCount = 1;
    vp.pScissors = &scissor;
    VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    rs.polygonMode = VK_POLYGON_MODE_FILL;
    rs.cullMode = VK_CULL_MODE_NONE;
    rs.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    ds.depthTestEnable = VK_TRUE;
    ds.depthWriteEnable = VK_TRUE;
    ds.depthCompareOp = reversed ? VK_COMPARE_OP_GREATER : VK_COMPARE_OP_LESS;
    VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    VkGraphicsPipelineCreateInfo gpci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    gpci.stageCount = 1;
    gpci.pStages = &vstage;
    gpci.pVertexInputState = &vin;
    gpci.pInputAssemblyState = &ia;
    gpci.pViewportState = &vp;
    gpci.pRasterizationState = &rs;
    gpci.pMultisampleState = &ms;
    gpci.pDepthStencilState = &ds;
    gpci.pColorBlendState = &cb;
    gpci.layout = pipelineLayout;
    gpci.renderPass = renderPass;
    VkPipeline depthPipeline;
    CHECK(vkCreateGraphicsPipelines(g.device, VK_NULL_HANDLE, 1, &gpci, nullptr, &depthPipeline));
    const std::uint32_t bugValue = bug ? 1u : 0u;
    VkSpecializationMapEntry entry{0, 0, 4};
    VkSpecializationInfo spec{1, &entry, 4, &bugValue};
    VkComputePipelineCreateInfo cpci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    cpci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    cpci.stage.module = cs;
    cpci.stage.pName = "main";
    cpci.stage.pSpecializationInfo = &spec;
    cpci.layout = pipelineLayout;
    VkPipeline cullPipeline;
    CHECK(vkCreateComputePipelines(g.device, VK_NULL_HANDLE, 1, &cpci, nullptr, &cullPipeline));
    g.name(VK_OBJECT_TYPE_PIPELINE, reinterpret_cast<std::uint64_t>(cullPipeline), "LightCullingPipeline");

    // The frame, captured.
    VkCommandPoolCreateInfo cpi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    cpi.queueFamilyIndex = g.family;
    VkCommandPool cmdPool;
    CHECK(vkCreateCommandPool(g.device, &cpi, nullptr, &cmdPool));
    VkCommandBufferAllocateInfo cbai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cbai.commandPool = cmdPool;
    cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbai.commandBufferCount = 1;
    VkCommandBuffer cmd;
    CHECK(vkAllocateCommandBuffers(g.device, &cbai, &cmd));
    const auto label = [&](const char* text) {
        if (!g.beginLabel) return;
        VkDebugUtilsLabelEXT l{VK_STRUCTURE_TYPE_DEBUG_UTILS_LABEL_EXT};
        l.pLabelName = text;
        g.beginLabel(cmd, &l);
    };
    const auto endLabel = [&] {
        if (g.endLabel) g.endLabel(cmd);
    };

    rdoc->StartFrameCapture(RENDERDOC_DEVICEPOINTER_FROM_VKINSTANCE(g.instance), nullptr);
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    CHECK(vkBeginCommandBuffer(cmd, &bi));
    label("Depth pre-pass");
    VkClearValue clear{};
    clear.depthStencil.depth = reversed ? 0.0f : 1.0f;
    VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    rbi.renderPass = renderPass;
    rbi.framebuffer = framebuffer;
    rbi.renderArea = {{0, 0}, {kWidth, kHeight}};
    rbi.clearValueCount = 1;
    rbi.pClearValues = &clear;
    vkCmdBeginRenderPass(cmd, &rbi, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, depthPipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelineLayout, 0, 1, &set, 0, nullptr);
    VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(cmd, 0, 1, &vertices.buffer, &offset);
    vkCmdDraw(cmd, std::uint32_t(tris.size()), 1, 0, 0);
    vkCmdEndRenderPass(cmd);
    endLabel();
    label("Forward+ light culling");
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, cullPipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 0, 1, &set, 0, nullptr);
    vkCmdDispatch(cmd, tilesX, tilesY, 1);
    endLabel();
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr,
                         0, nullptr);
    CHECK(vkEndCommandBuffer(cmd));
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    CHECK(vkQueueSubmit(g.queue, 1, &si, VK_NULL_HANDLE));
    CHECK(vkQueueWaitIdle(g.queue));
    if (!rdoc->EndFrameCapture(RENDERDOC_DEVICEPOINTER_FROM_VKINSTANCE(g.instance), nullptr)) {
        std::fprintf(stderr, "mini_engine: RenderDoc did not capture the frame\n");
        return 1;
    }
    char written[4096];
    std::uint32_t len = sizeof written;
    rdoc->GetCapture(rdoc->GetNumCaptures() - 1, written, &len, nullptr);
    std::filesystem::rename(written, capturePath);
    std::filesystem::remove_all(captureDir);

    // The lists this renderer culled, as it reads them back.
    std::ofstream csv(argv[2]);
    csv << "list,lights\n";
    const auto* c = static_cast<const std::uint32_t*>(counts.mapped);
    const auto* idx = static_cast<const std::uint32_t*>(indices.mapped);
    for (std::uint32_t t = 0; t < tiles; ++t) {
        csv << t;
        for (std::uint32_t k = 0; k < c[t] && k < kMaxLights; ++k) csv << "," << idx[t * kMaxLights + k];
        csv << "\n";
    }
    vkDeviceWaitIdle(g.device);
    std::printf("mini_engine: %ux%u, %u tiles, %u lights, %s depth%s; capture %s\n", kWidth, kHeight, tiles, kLights,
                reversed ? "reversed" : "standard", bug ? ", half-radius bug" : "", capturePath.c_str());
    return g_messages == 0 ? 0 : 1;
}
