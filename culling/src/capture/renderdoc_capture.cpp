#include "culling/capture/renderdoc_capture.hpp"

#include "culling/core/errors.hpp"
#include "culling/core/file_io.hpp"

#include <renderdoc_app.h>

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <vector>

namespace fs = std::filesystem;

namespace lc {

struct RenderDocCapture::Impl {
    void* library = nullptr;
    RENDERDOC_API_1_6_0* api = nullptr;
    bool capturing = false;
    void* device = nullptr; // RenderDoc's device pointer of the capture, null: any
    std::string path, title;
    bool written = false;
};

namespace {

RenderDocCapture* g_active = nullptr;

std::string libraryPath() {
    if (const char* p = std::getenv("LIGHTCULL_RENDERDOC_LIBRARY"); p && *p) return p;
    return "librenderdoc.so";
}

} // namespace

RenderDocCapture::RenderDocCapture(const std::string& path, const std::string& title)
    : impl_(std::make_unique<Impl>()) {
    impl_->path = path;
    impl_->title = title;
    const std::string lib = libraryPath();
    // Already in the process (started from RenderDoc's UI or renderdoccmd):
    // use that one, whatever it was loaded as.
    impl_->library = dlopen("librenderdoc.so", RTLD_NOW | RTLD_NOLOAD);
    if (!impl_->library) {
        if (vulkanInstanceCreated())
            throw DeviceError("RenderDoc must be loaded before the first Vulkan instance of this process; "
                              "start the capture before opening a Vulkan device");
        // RenderDoc's Vulkan layer is implicit and enabled by this variable
        // (its manifest, /usr/share/vulkan/implicit_layer.d/renderdoc_capture.json).
        setenv("ENABLE_VULKAN_RENDERDOC_CAPTURE", "1", 1);
        impl_->library = dlopen(lib.c_str(), RTLD_NOW | RTLD_GLOBAL);
    }
    if (!impl_->library)
        throw DeviceError("cannot load RenderDoc (" + lib + "): install it (Debian 12: apt-get install librenderdoc) "
                          "or set LIGHTCULL_RENDERDOC_LIBRARY to its librenderdoc.so");
    auto getApi = reinterpret_cast<pRENDERDOC_GetAPI>(dlsym(impl_->library, "RENDERDOC_GetAPI"));
    void* api = nullptr;
    if (!getApi || !getApi(eRENDERDOC_API_Version_1_6_0, &api) || !api)
        throw DeviceError(lib + " is not a RenderDoc library with the in-application API 1.6 (RenderDoc 1.24 or later)");
    impl_->api = static_cast<RENDERDOC_API_1_6_0*>(api);
    // Every resource in the capture, used or not: a user looking for a
    // binding should find it even when this frame did not touch it.
    impl_->api->SetCaptureOptionU32(eRENDERDOC_Option_RefAllResources, 1);
    impl_->api->SetCaptureOptionU32(eRENDERDOC_Option_CaptureCallstacks, 0);
    g_active = this;
}

RenderDocCapture* RenderDocCapture::active() { return g_active; }

bool RenderDocCapture::capturing() const { return impl_->capturing; }

void RenderDocCapture::startOnInstance(void* vkInstance) {
    if (impl_->capturing || impl_->written) return;
    impl_->device = RENDERDOC_DEVICEPOINTER_FROM_VKINSTANCE(vkInstance);
    impl_->api->StartFrameCapture(impl_->device, nullptr);
    impl_->capturing = true;
}

RenderDocCapture::~RenderDocCapture() {
    if (g_active == this) g_active = nullptr;
    if (impl_->capturing) discard();
    // The library stays loaded: RenderDoc does not support being unloaded
    // while its hooks are in place.
}

std::string RenderDocCapture::version() const {
    int a = 0, b = 0, c = 0;
    impl_->api->GetAPIVersion(&a, &b, &c);
    return std::to_string(a) + "." + std::to_string(b) + "." + std::to_string(c);
}

void RenderDocCapture::start() {
    if (impl_->capturing || impl_->written) throw DeviceError("a RenderDoc capture is already running");
    impl_->device = nullptr;
    impl_->api->StartFrameCapture(nullptr, nullptr);
    impl_->capturing = true;
}

void RenderDocCapture::discard() {
    if (!impl_->capturing) return;
    impl_->api->DiscardFrameCapture(impl_->device, nullptr);
    impl_->capturing = false;
}

void RenderDocCapture::finish() {
    if (impl_->written) return;
    if (!impl_->capturing) throw DeviceError("RenderDoc wrote no capture: no Vulkan work was captured");
    const std::string& path = impl_->path;
    checkFileTarget(path);
    // RenderDoc names its files from a template; they go into a temporary
    // folder beside `path`, and the one written is renamed onto it.
    const fs::path target = fs::absolute(path);
    std::string tmpl = (target.parent_path() / ("." + target.filename().string() + ".rdc-XXXXXX")).string();
    std::vector<char> buf(tmpl.begin(), tmpl.end());
    buf.push_back('\0');
    if (!mkdtemp(buf.data())) throw Error("cannot write " + path + ": cannot create a temporary folder beside it");
    const fs::path tmp(buf.data());
    const auto cleanup = [&] {
        std::error_code ec;
        fs::remove_all(tmp, ec);
    };
    impl_->api->SetCaptureFilePathTemplate((tmp / "capture").c_str());
    impl_->api->SetCaptureTitle(impl_->title.c_str());
    const std::uint32_t before = impl_->api->GetNumCaptures();
    const std::uint32_t ok = impl_->api->EndFrameCapture(impl_->device, nullptr);
    impl_->capturing = false;
    if (!ok || impl_->api->GetNumCaptures() <= before) {
        cleanup();
        throw DeviceError("RenderDoc wrote no capture (no Vulkan work on the captured device)");
    }
    std::uint32_t len = 0;
    impl_->api->GetCapture(impl_->api->GetNumCaptures() - 1, nullptr, &len, nullptr);
    std::vector<char> name(len + 1, '\0');
    impl_->api->GetCapture(impl_->api->GetNumCaptures() - 1, name.data(), &len, nullptr);
    std::error_code ec;
    fs::rename(fs::path(name.data()), target, ec);
    if (ec) {
        cleanup();
        throw Error("cannot write " + path + ": " + ec.message());
    }
    cleanup();
    syncFolder(target.parent_path().string());
    impl_->written = true;
}

} // namespace lc
