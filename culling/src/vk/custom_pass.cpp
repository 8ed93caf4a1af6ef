// A user's culling compute shader on a Vulkan device of its own: compiled at
// run time with glslang (GLSL or HLSL) or taken as SPIR-V, bound to the
// inputs docs/CUSTOM_CULLING.md fixes, dispatched one workgroup per tile with
// robust buffer access and (by default) the validation layer on, waited for
// with a time limit, read back and decoded into a CullResult.
#include "culling/capture/renderdoc_capture.hpp"
#include "culling/custom/custom_cull.hpp"

#include "culling/core/errors.hpp"
#include "custom/custom_internal.hpp"
#include "vk/validation.hpp"
#include "vk/vk_context.hpp"

// Vulkan create-info structs are filled field by field (as in vk_context.cpp).
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <regex>
#include <set>
#include <sstream>

namespace lc {

extern const char* const kCustomCullingHeader; // shaders/custom/lightcull.glsl, embedded at build time

namespace {

namespace fs = std::filesystem;

// The uniform block of binding 0 (std140; lightcull.glsl's LcParamsBlock).
struct CustomParams {
    glm::uvec4 size;
    glm::uvec4 counts;
    glm::uvec4 mode;
    glm::vec4 depthParams;
    glm::vec4 planes;
    glm::vec4 lens;
    glm::mat4 proj;
    glm::mat4 invProj;
};
static_assert(sizeof(CustomParams) == 224, "CustomParams must match LcParamsBlock (std140)");
static_assert(offsetof(CustomParams, lens) == 80, "CustomParams.lens offset");
static_assert(offsetof(CustomParams, proj) == 96, "CustomParams.proj offset");

// lightcull.glsl's LcLight (std430).
struct CustomLight {
    glm::vec4 positionRadius;
    glm::vec4 spotAxisAngle;
};
static_assert(sizeof(CustomLight) == 32, "CustomLight must match LcLight (std430)");

void initGlslang() {
    static std::once_flag once;
    std::call_once(once, [] { glslang::InitializeProcess(); });
}

// Serves "lightcull.glsl" from the build, anything else from the shader's folder.
class Includer : public glslang::TShader::Includer {
public:
    explicit Includer(fs::path dir) : dir_(std::move(dir)) {}
    IncludeResult* includeLocal(const char* name, const char*, size_t depth) override { return include(name, depth); }
    IncludeResult* includeSystem(const char* name, const char*, size_t depth) override { return include(name, depth); }
    void releaseInclude(IncludeResult* r) override {
        if (r) delete static_cast<std::string*>(r->userData);
        delete r;
    }

private:
    IncludeResult* include(const char* name, size_t depth) {
        if (depth > 16) return nullptr;
        auto* text = new std::string;
        std::string resolved = name;
        if (std::string(name) == "lightcull.glsl") {
            *text = kCustomCullingHeader;
        } else {
            const fs::path p = dir_ / name;
            std::ifstream in(p, std::ios::binary);
            if (!in) {
                delete text;
                return nullptr;
            }
            std::ostringstream ss;
            ss << in.rdbuf();
            *text = ss.str();
            resolved = p.string();
        }
        return new IncludeResult(resolved, text->data(), text->size(), text);
    }
    fs::path dir_;
};

// glslang's first "ERROR: file:line: message" as file:line: message.
[[noreturn]] void throwCompileError(const std::string& path, const std::string& log, const char* stage) {
    static const std::regex re(R"(ERROR: ([^\n]*?):(\d+): ([^\n]*))");
    std::smatch m;
    if (std::regex_search(log, m, re)) {
        const std::string file = m[1].str() == path || m[1].str().empty() ? path : m[1].str();
        throw InputError(file, "", std::stoi(m[2].str()), std::string(stage) + ": " + m[3].str());
    }
    std::string first = log.substr(0, log.find('\n'));
    if (first.rfind("ERROR: ", 0) == 0) first = first.substr(7);
    throw InputError(path, "", 0, std::string(stage) + ": " + (first.empty() ? "failed" : first));
}

std::vector<std::uint32_t> compileSource(const std::string& path, const std::string& text, bool hlsl,
                                         const std::string& entry, const std::string& preamble) {
    initGlslang();
    glslang::TShader shader(EShLangCompute);
    const char* strings[] = {text.c_str()};
    const int lengths[] = {int(text.size())};
    const char* names[] = {path.c_str()};
    shader.setStringsWithLengthsAndNames(strings, lengths, names, 1);
    shader.setPreamble(preamble.c_str());
    shader.setEnvInput(hlsl ? glslang::EShSourceHlsl : glslang::EShSourceGlsl, EShLangCompute, glslang::EShClientVulkan,
                       100);
    shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_1);
    shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_3);
    if (hlsl) {
        shader.setEntryPoint(entry.c_str());
        shader.setSourceEntryPoint(entry.c_str());
    }
    auto messages = EShMessages(EShMsgSpvRules | EShMsgVulkanRules | (hlsl ? int(EShMsgReadHlsl) : 0));
    Includer includer(fs::path(path).parent_path());
    if (!shader.parse(GetDefaultResources(), hlsl ? 100 : 450, false, messages, includer))
        throwCompileError(path, shader.getInfoLog(), "compile error");
    glslang::TProgram program;
    program.addShader(&shader);
    if (!program.link(messages)) throwCompileError(path, program.getInfoLog(), "link error");
    // glslang only warns of an HLSL entry point it did not find, and emits an
    // empty function of that name: a shader that writes no list.
    if (hlsl && std::string(program.getInfoLog()).find("Entry point not found") != std::string::npos)
        throw InputError(path, "", 0, "no function '" + entry + "' to use as the entry point (--entry, or the file's "
                                      "'// lightcull:' line; docs/CUSTOM_CULLING.md)");
    std::vector<std::uint32_t> spirv;
    spv::SpvBuildLogger logger;
    glslang::SpvOptions opts;
    opts.generateDebugInfo = false;
    glslang::GlslangToSpv(*program.getIntermediate(EShLangCompute), spirv, &logger, &opts);
    if (spirv.empty()) throw InputError(path, "", 0, "no SPIR-V generated: " + logger.getAllMessages());
    return spirv;
}

std::string definesFor(const CustomShaderOptions& o, const TileGrid& grid, std::uint32_t listsPerTile,
                       std::uint32_t lightCount, std::uint64_t compactEntries) {
    std::ostringstream d;
    d << "#define TILE_SIZE " << grid.tileSize << "\n";
    d << "#define MAX_LIGHTS_PER_TILE " << (o.layout.kind == ListLayout::Fixed ? o.layout.capacity : 0u) << "\n";
    d << "#define LC_LAYOUT " << int(o.layout.kind) << "\n";
    d << "#define LC_LISTS " << int(o.lists.kind) << "\n";
    d << "#define LC_LISTS_PER_TILE " << listsPerTile << "\n";
    d << "#define LC_MASK_WORDS " << std::max<std::uint32_t>(1, (lightCount + 31) / 32) << "\n";
    d << "#define LC_COMPACT_ENTRIES " << compactEntries << "\n";
    return d.str();
}

std::vector<std::uint32_t> loadSpirv(const std::string& path) {
    const std::string bytes = detail::readWholeFile(path);
    if (bytes.size() < 20 || bytes.size() % 4 != 0)
        throw InputError(path, "", 0, "not SPIR-V: " + std::to_string(bytes.size()) + " bytes is not a whole module");
    std::vector<std::uint32_t> words(bytes.size() / 4);
    std::memcpy(words.data(), bytes.data(), bytes.size());
    if (words[0] != 0x07230203u) throw InputError(path, "", 0, "not SPIR-V: wrong magic number");
    return words;
}

// What the contract fixes that the device would otherwise be asked to accept
// on trust: a compute entry point of the name the pipeline names, and only
// the five bindings of set 0 (a resource the pipeline layout lacks is
// undefined behaviour that crashes the validation layer; without it the
// shader reads nothing). Read from the module's instructions: OpEntryPoint,
// and the DescriptorSet / Binding decorations and storage class of its
// variables.
void checkInterface(const std::string& path, const std::vector<std::uint32_t>& words, const std::string& entry) {
    constexpr std::uint32_t kOpEntryPoint = 15, kOpTypePointer = 32, kOpVariable = 59, kOpDecorate = 71;
    constexpr std::uint32_t kGLCompute = 5, kDecBinding = 33, kDecDescriptorSet = 34, kDecBufferBlock = 3;
    constexpr std::uint32_t kUniformConstant = 0, kUniform = 2, kPushConstant = 9, kStorageBuffer = 12;
    std::vector<std::string> computeEntries;
    std::map<std::uint32_t, std::uint32_t> bindingOf, setOf;
    // What each variable is: its storage class and pointer type; what each
    // pointer points to; the structs decorated BufferBlock (a storage buffer
    // in the Uniform class, as older GLSL compilers and HLSL emit them).
    std::map<std::uint32_t, std::uint32_t> classOf, typeOf, pointee;
    std::set<std::uint32_t> bufferBlocks;
    bool pushConstants = false;
    for (std::size_t i = 5; i < words.size();) {
        const std::uint32_t count = words[i] >> 16, op = words[i] & 0xFFFFu;
        if (count == 0 || count > words.size() - i)
            throw InputError(path, "", 0, "not SPIR-V: instruction at word " + std::to_string(i) + " runs past the module");
        const std::uint32_t* w = &words[i];
        if (op == kOpEntryPoint && count >= 4 && w[1] == kGLCompute) {
            // The name: a nul-terminated string packed into words from w[3].
            std::string name;
            for (std::size_t k = 3 * 4; k < std::size_t(count) * 4; ++k) {
                const char c = char((w[k / 4] >> (8 * (k % 4))) & 0xFFu);
                if (c == '\0') break;
                name += c;
            }
            computeEntries.push_back(name);
        } else if (op == kOpDecorate && count >= 4 && w[2] == kDecBinding) {
            bindingOf[w[1]] = w[3];
        } else if (op == kOpDecorate && count >= 4 && w[2] == kDecDescriptorSet) {
            setOf[w[1]] = w[3];
        } else if (op == kOpDecorate && count >= 3 && w[2] == kDecBufferBlock) {
            bufferBlocks.insert(w[1]);
        } else if (op == kOpTypePointer && count >= 4) {
            pointee[w[1]] = w[3];
        } else if (op == kOpVariable && count >= 4) {
            pushConstants = pushConstants || w[3] == kPushConstant;
            typeOf[w[2]] = w[1];
            classOf[w[2]] = w[3];
        }
        i += count;
    }
    if (std::find(computeEntries.begin(), computeEntries.end(), entry) == computeEntries.end()) {
        std::string have;
        for (const auto& e : computeEntries) have += (have.empty() ? "'" : ", '") + e + "'";
        throw InputError(path, "", 0, "no compute entry point '" + entry + "' (the module has " +
                                          (have.empty() ? std::string("none") : have) + "; --entry)");
    }
    if (pushConstants)
        throw InputError(path, "", 0, "declares push constants: the contract has none (the parameters are binding 0)");
    static const char* const kBindings = "0 parameters, 1 depth texture, 2 depth buffer, 3 lights, 4 lists";
    for (const auto& [id, binding] : bindingOf) {
        const auto set = setOf.find(id);
        const std::uint32_t s = set == setOf.end() ? 0 : set->second;
        if (s != 0 || binding > 4)
            throw InputError(path, "", 0, "declares set " + std::to_string(s) + " binding " + std::to_string(binding) +
                                              ", which the contract does not bind (set 0: " + kBindings +
                                              "; docs/CUSTOM_CULLING.md)");
        // The kind of resource at that binding: a mismatch reads nothing
        // (and without the validation layer says nothing).
        const auto cls = classOf.find(id);
        if (cls == classOf.end()) continue;
        const auto type = typeOf.find(id);
        const auto block = type == typeOf.end() ? pointee.end() : pointee.find(type->second);
        const char* declared = cls->second == kUniformConstant ? "a texture or sampler"
                               : cls->second == kStorageBuffer ? "a storage buffer"
                               : cls->second == kUniform
                                   ? (block != pointee.end() && bufferBlocks.count(block->second) ? "a storage buffer"
                                                                                                  : "a uniform buffer")
                                   : nullptr;
        const char* expected = binding == 0 ? "a uniform buffer" : binding == 1 ? "a texture or sampler"
                                                                                : "a storage buffer";
        if (declared && std::string(declared) != expected)
            throw InputError(path, "", 0, "declares binding " + std::to_string(binding) + " as " + declared +
                                              "; the contract binds " + expected + " there (set 0: " + kBindings +
                                              "; docs/CUSTOM_CULLING.md)");
    }
}

// The contract's bindings (docs/CUSTOM_CULLING.md): parameters, depth
// texture, depth buffer, lights, lists.
const std::vector<VkDescriptorType> kBindingTypes = {
    VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
    VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};

// A device for user shaders and what outlives one run on it: the
// contract's layouts and the pipelines of the shaders run on it (a device
// compiles a pipeline from SPIR-V: lavapipe through LLVM, most of a small
// run). A hunt's trials differ in their defines (tile size, light count,
// layout) far less often than in their scenes.
struct ShaderDevice {
    std::unique_ptr<vk::Context> ctx;
    vk::DescriptorSetLayoutHandle setLayout;
    vk::PipelineLayoutHandle pipelineLayout;
    struct Kept {
        vk::ShaderModuleHandle module;
        vk::PipelineHandle pipeline;
        std::uint64_t lastUse = 0;
        // What the validation layer said while the module and pipeline were
        // made: said again for every run that uses them.
        std::vector<std::string> messages;
    };
    std::map<std::string, Kept> pipelines; // key: entry point, NUL, the SPIR-V's bytes
    std::uint64_t uses = 0;
    // Members die in reverse order: the context, declared first, goes last.

    static constexpr std::size_t kMaxPipelines = 32;

    explicit ShaderDevice(const vk::ContextOptions& co) : ctx(std::make_unique<vk::Context>(co)) {
        auto layouts = ctx->createPassLayouts(kBindingTypes, "custom");
        setLayout = std::move(layouts.set);
        pipelineLayout = std::move(layouts.pipeline);
    }
};

std::atomic<std::uint64_t> pipelinesMade{0};

// The pipeline of `spirv` at `entry` on `sd`: kept from an earlier run, or
// made now (and the one used longest ago dropped beyond kMaxPipelines).
// `replayed`: a kept pipeline's validation messages from when it was made
// (a pipeline made now puts its own in the layer's list). Throws InputError
// when the device refuses it.
VkPipeline shaderPipeline(ShaderDevice& sd, const std::vector<std::uint32_t>& spirv, const std::string& entry,
                          const std::string& path, const std::function<std::string()>& firstMessage,
                          std::vector<std::string>& replayed) {
    std::string key = entry;
    key.push_back('\0');
    key.append(reinterpret_cast<const char*>(spirv.data()), spirv.size() * 4);
    ++sd.uses;
    if (auto it = sd.pipelines.find(key); it != sd.pipelines.end()) {
        it->second.lastUse = sd.uses;
        replayed = it->second.messages;
        return it->second.pipeline;
    }
    const std::size_t messagesBefore = vk::validationMessages().size();
    const VkDevice dev = sd.ctx->device();
    ShaderDevice::Kept k;
    k.module = sd.ctx->createShader(spirv.data(), spirv.size(), "custom.shader");
    VkComputePipelineCreateInfo cpi{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    cpi.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    cpi.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    cpi.stage.module = k.module;
    cpi.stage.pName = entry.c_str();
    cpi.layout = sd.pipelineLayout;
    VkPipeline pipe;
    const VkResult pr = vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &cpi, nullptr, &pipe);
    if (pr != VK_SUCCESS)
        throw InputError(path, "", 0, std::string("the device refused the pipeline (") + vk::resultName(pr) +
                                          "): check the entry point '" + entry + "' and the bindings" + firstMessage());
    ++pipelinesMade;
    k.pipeline = vk::PipelineHandle(dev, pipe);
    k.lastUse = sd.uses;
    const std::vector<std::string> messages = vk::validationMessages();
    if (messages.size() > messagesBefore)
        k.messages.assign(messages.begin() + std::ptrdiff_t(messagesBefore), messages.end());
    if (sd.pipelines.size() >= ShaderDevice::kMaxPipelines) {
        auto oldest = sd.pipelines.begin();
        for (auto it = sd.pipelines.begin(); it != sd.pipelines.end(); ++it)
            if (it->second.lastUse < oldest->second.lastUse) oldest = it;
        sd.pipelines.erase(oldest); // no run uses it: the device is this run's alone
    }
    return sd.pipelines.emplace(std::move(key), std::move(k)).first->second.pipeline;
}

// Everything created on the device for one run, owned together so that a
// hang can leak all of it at once (see Context::submitAndWaitFor).
struct RunState {
    std::unique_ptr<ShaderDevice> sd;
    vk::Buffer params, depthBuf, lightBuf, out, staging;
    vk::Image depthImage;
    vk::DeviceHandle<VkSampler, vkDestroySampler> sampler;
    vk::DescriptorPoolHandle pool;
    // Members die in reverse order: the device, declared first, goes last.
};

// The device a finished run leaves for the next one. A hunt or a report
// runs one shader hundreds of times, and opening an instance and a device
// (the validation layer's set-up with it) and closing them again was most
// of each run on lavapipe. One device is kept, for the options it was
// opened with (the environment variables the context reads included); a run
// takes it when its options match and gives it back only when it finished
// (a hang abandons its device, an error closes it). Never destroyed: at exit
// the drivers' own exit handlers may already have stopped their threads.
class IdleDevice {
public:
    std::unique_ptr<ShaderDevice> take(const vk::ContextOptions& co) {
        const std::string k = key(co);
        {
            std::lock_guard<std::mutex> lock(mutex_);
            if (sd_ && key_ == k) return std::move(sd_);
        }
        ++opened_;
        return std::make_unique<ShaderDevice>(co);
    }
    void giveBack(std::unique_ptr<ShaderDevice> sd, const vk::ContextOptions& co) {
        std::unique_ptr<ShaderDevice> old; // closed outside the lock
        std::lock_guard<std::mutex> lock(mutex_);
        old = std::move(sd_);
        sd_ = std::move(sd);
        key_ = key(co);
    }
    std::uint64_t opened() const { return opened_; }

private:
    static std::string key(const vk::ContextOptions& co) {
        auto env = [](const char* name) {
            const char* v = std::getenv(name);
            return v ? std::string("=") + v : std::string("unset");
        };
        return co.device + '\n' + co.purpose + '\n' + char('0' + co.validation) + char('0' + co.robustAccess) + '\n' +
               env("LIGHTCULL_DEVICE") + '\n' + env("LIGHTCULL_VALIDATION") + '\n' + env("LIGHTCULL_VK_EMULATE_GPU") +
               '\n' + env("LIGHTCULL_VK_NO_CONSERVATIVE");
    }
    std::mutex mutex_;
    std::unique_ptr<ShaderDevice> sd_;
    std::string key_;
    std::atomic<std::uint64_t> opened_{0};
};

IdleDevice& idleDevice() {
    static auto* kept = new IdleDevice; // NOLINT: deliberately never destroyed (see above)
    return *kept;
}

} // namespace

CustomShaderDeviceCount customShaderDevices() { return {idleDevice().opened(), pipelinesMade}; }

namespace {

// The contract's parameters (docs/CUSTOM_CULLING.md): grid, counts, modes,
// depth linearisation, planes, lens and matrices.
CustomParams customParams(const CustomShaderOptions& o, const Projection& proj, const TileGrid& grid,
                          const CullResult& skeleton, std::uint32_t lightCount, std::uint64_t compactEntries) {
    const auto listCount = std::uint32_t(skeleton.listOffset.size());
    CustomParams params{};
    params.size = {grid.width, grid.height, grid.tilesX, grid.tilesY};
    const std::uint32_t capacity = o.layout.kind == ListLayout::Fixed   ? o.layout.capacity
                                   : o.layout.kind == ListLayout::Bitmask ? std::max<std::uint32_t>(1, (lightCount + 31) / 32)
                                                                          : std::uint32_t(compactEntries);
    params.counts = {lightCount, skeleton.listsPerTile, listCount, capacity};
    params.mode = {std::uint32_t(proj.kind()), std::uint32_t(o.layout.kind), std::uint32_t(o.lists.kind),
                   std::uint32_t(o.lists.slicing)};
    const DepthParams dp = proj.depthParams();
    params.depthParams = {dp.ab_ortho_clear.x, dp.ab_ortho_clear.y, dp.ab_ortho_clear.z, dp.ab_ortho_clear.w};
    params.planes = {float(proj.nearPlane()), std::isinf(proj.farPlane()) ? 0.0f : float(proj.farPlane()),
                     float(skeleton.clusterNear), float(skeleton.clusterFar)};
    const glm::dvec3 corner = proj.viewPositionAt({double(proj.width()), 0.0}, 1.0);
    params.lens = {float(corner.x), float(corner.y), proj.orthographic() ? 1.0f : 0.0f, 0.0f};
    params.proj = glm::mat4(proj.clipFromView());
    params.invProj = glm::mat4(glm::inverse(proj.clipFromView()));
    return params;
}

// The shader's SPIR-V: as given (.spv), or GLSL / HLSL compiled with the
// contract's defines. `entry`: the entry point the pipeline takes.
std::vector<std::uint32_t> shaderWords(const CustomShaderOptions& o, const TileGrid& grid, const CullResult& skeleton,
                                       std::uint32_t lightCount, std::uint64_t compactEntries, std::string& entry) {
    const std::string ext = fs::path(o.path).extension().string();
    if (ext == ".spv") return loadSpirv(o.path);
    const bool hlsl = ext == ".hlsl";
    if (!hlsl) entry = "main";
    return compileSource(o.path, detail::withoutByteOrderMark(detail::readWholeFile(o.path)), hlsl, o.entry,
                         definesFor(o, grid, skeleton.listsPerTile, lightCount, compactEntries));
}

// The depth texture (binding 1), from the depth buffer through a copy.
void uploadDepthTexture(RunState& rs, const DepthImage& depth) {
    RunState* st = &rs;
    const vk::Context& ctx = *st->sd->ctx;
    const VkDevice dev = ctx.device();
    st->depthImage = ctx.createImage(depth.width, depth.height, VK_FORMAT_R32_SFLOAT,
                                     VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                                     VK_IMAGE_ASPECT_COLOR_BIT, "custom.depthTexture");
    VkSamplerCreateInfo sci{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    sci.magFilter = sci.minFilter = VK_FILTER_NEAREST;
    sci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    VkSampler sampler;
    LC_VK(vkCreateSampler(dev, &sci, nullptr, &sampler));
    st->sampler = vk::DeviceHandle<VkSampler, vkDestroySampler>(dev, sampler);
    st->sd->ctx->submitAndWait(
        [&](VkCommandBuffer cmd) {
            VkImageMemoryBarrier toDst{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
            // Hazard: the copy must not start before the image leaves UNDEFINED.
            toDst.srcAccessMask = 0;
            toDst.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
            toDst.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
            toDst.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
            toDst.srcQueueFamilyIndex = toDst.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            toDst.image = st->depthImage.image;
            toDst.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
            vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr,
                                 0, nullptr, 1, &toDst);
            VkBufferImageCopy region{};
            region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            region.imageExtent = {depth.width, depth.height, 1};
            vkCmdCopyBufferToImage(cmd, st->depthBuf.buffer, st->depthImage.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                   1, &region);
            VkImageMemoryBarrier toRead = toDst;
            // Hazard: the shader's reads must see the finished copy.
            toRead.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
            toRead.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
            toRead.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
            toRead.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
            vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0,
                                 nullptr, 0, nullptr, 1, &toRead);
        },
        "custom.uploadDepth");

}

} // namespace

CullResult runCustomShader(const CustomShaderOptions& o, const DepthImage& depth, const Projection& proj,
                           const TileGrid& grid, const ViewLights& lights, CustomCullReport& report) {
    report.source = o.path;
    report.layout = toString(o.layout);
    if (!o.headerLayout.empty() && o.headerLayout != report.layout) report.headerLayout = o.headerLayout;
    report.lists = toString(o.lists);
    const auto lightCount = std::uint32_t(lights.size());

    // The list rule's CPU reference: grid, tile bounds, halfz splits, froxel
    // range, and the lists a built-in algorithm of that rule makes.
    const CullResult skeleton = detail::ruleSkeleton(depth, proj, grid, lights, o.lists);
    const auto listCount = std::uint32_t(skeleton.listOffset.size());
    const std::uint64_t compactEntries =
        o.layout.kind == ListLayout::Compact ? (o.layout.capacity ? o.layout.capacity : 64ull * listCount) : 0;
    const std::uint64_t outWords = layoutWords(o.layout, listCount, lightCount);
    if (outWords * 4 > (std::uint64_t(1) << 30))
        throw SettingsError("layout", toString(o.layout) + " needs " + std::to_string(outWords * 4 >> 20) +
                                          " MiB of lists here; more than the 1 GiB allowed");

    // The shader: SPIR-V as given, or compiled with the contract's defines.
    std::string entry = o.entry;
    const std::vector<std::uint32_t> spirv = shaderWords(o, grid, skeleton, lightCount, compactEntries, entry);
    checkInterface(o.path, spirv, entry);

    const std::size_t messagesBefore = vk::validationMessages().size();
    // Whatever the layer says during this run is the shader's report, not a
    // failure of the built-in passes: taken out of the global list on every path.
    struct TakeMessages {
        std::size_t from;
        ~TakeMessages() { vk::eraseValidationMessagesFrom(from); }
    } takeMessages{messagesBefore};
    auto firstMessage = [&]() -> std::string {
        const auto m = vk::validationMessages();
        return m.size() > messagesBefore ? "; validation: " + m[messagesBefore] : std::string();
    };
    auto st = std::make_unique<RunState>();
    vk::ContextOptions co;
    co.device = o.device;
    co.purpose = "lc.custom";
    co.validation = o.validation;
    co.robustAccess = true;
    // A RenderDoc capture hooks the instance it is started on when it is
    // created: such a run opens its own.
    RenderDocCapture* capture = RenderDocCapture::active();
    if (capture && !capture->capturesCustomShader()) capture = nullptr;
    st->sd = capture ? std::make_unique<ShaderDevice>(co) : idleDevice().take(co);
    const vk::Context& ctx = *st->sd->ctx;
    report.device = ctx.deviceName();

    // Inputs.
    const CustomParams params = customParams(o, proj, grid, skeleton, lightCount, compactEntries);
    st->params = ctx.createBuffer(sizeof params, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, "custom.params");
    std::memcpy(st->params.mapped, &params, sizeof params);

    const std::size_t pixels = std::size_t(depth.width) * depth.height;
    st->depthBuf = ctx.createBuffer(pixels * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                    "custom.depthBuffer");
    std::memcpy(st->depthBuf.mapped, depth.depth.data(), pixels * 4);

    std::vector<CustomLight> gl(lightCount);
    for (std::uint32_t i = 0; i < lightCount; ++i) {
        gl[i].positionRadius = glm::vec4(glm::vec3(lights.centers[i]), float(lights.radii[i]));
        if (lights.isSpot(i))
            gl[i].spotAxisAngle = glm::vec4(glm::vec3(lights.spotAxes[i]), float(lights.spotAngles[i]));
    }
    st->lightBuf = ctx.createBuffer(std::max<std::size_t>(gl.size(), 1) * sizeof(CustomLight),
                                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "custom.lights");
    if (!gl.empty()) std::memcpy(st->lightBuf.mapped, gl.data(), gl.size() * sizeof(CustomLight));
    st->out = ctx.createReadbackBuffer(
        outWords * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, "custom.lists");

    uploadDepthTexture(*st, depth);

    // Pipeline, descriptors.
    std::vector<std::string> replayed;
    const VkPipeline pipeline = shaderPipeline(*st->sd, spirv, entry, o.path, firstMessage, replayed);
    std::vector<vk::Context::DescriptorWrite> bindings(5);
    const VkBuffer buffers[5] = {st->params.buffer, VK_NULL_HANDLE, st->depthBuf.buffer, st->lightBuf.buffer,
                                 st->out.buffer};
    for (std::uint32_t i = 0; i < 5; ++i) {
        bindings[i].type = kBindingTypes[i];
        bindings[i].buffer = buffers[i];
    }
    bindings[1].image = {st->sampler, st->depthImage.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    st->pool = ctx.createDescriptorPool(bindings, 1, "custom.descriptorPool");
    VkDescriptorSet set = ctx.writeDescriptorSet(st->pool, st->sd->setLayout, bindings, "custom.set");

    // `run --renderdoc-capture --shader`: this device is the one captured,
    // and the capture must end before the device is destroyed.
    if (capture) capture->startOnInstance(ctx.instance());
    double wallMs = 0;
    const bool finished = st->sd->ctx->submitAndWaitFor(
        [&](VkCommandBuffer cmd) {
            vkCmdFillBuffer(cmd, st->out.buffer, 0, VK_WHOLE_SIZE, 0);
            // Hazard: the shader's list writes and atomics must follow the zero fill.
            vk::memoryBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                              VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                              VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
            vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, st->sd->pipelineLayout, 0, 1, &set, 0,
                                    nullptr);
            vkCmdDispatch(cmd, grid.tilesX, grid.tilesY, 1);
            // Hazard: the host reads the lists only after the shader's writes.
            vk::memoryBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                              VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
        },
        "custom.cull", o.timeoutMs, wallMs);
    if (!finished) {
        // The device is still running the shader: leak everything it uses (a
        // CPU device keeps one thread busy until the process ends) and let
        // the next run open a fresh device.
        (void)st.release();
        throw DeviceError(o.path + ": the culling shader did not finish within " + std::to_string(int(o.timeoutMs)) +
                          " ms, the time limit for one dispatch (a slow shader on this device, or one that never "
                          "ends): raise it with --timeout-ms; that device was abandoned and the next run opens a "
                          "fresh one");
    }
    report.passMs = wallMs;
    if (capture) capture->finish();

    std::vector<std::uint32_t> words(outWords);
    std::memcpy(words.data(), st->out.mapped, outWords * 4);
    std::unique_ptr<ShaderDevice> used = std::move(st->sd);
    st.reset(); // the run's objects, before their device goes back
    if (!capture) idleDevice().giveBack(std::move(used), co);
    std::vector<std::string> messages = vk::validationMessages();
    report.validationMessages = replayed;
    if (messages.size() > messagesBefore)
        report.validationMessages.insert(report.validationMessages.end(),
                                         messages.begin() + std::ptrdiff_t(messagesBefore), messages.end());

    CullResult r = skeleton;
    decodeLists(words, o.layout, lightCount, r, report);
    detail::compareWithBuiltin(r, skeleton, report);
    r.backend = "custom";
    r.device = report.device;
    r.timingMethod = "cpu-wall-clock around vkQueueSubmit+vkWaitForFences (custom shader dispatch)";
    r.timings = Timings{};
    r.timings.cullMs = wallMs;
    r.volumeTests = 0;
    return r;
}

} // namespace lc
