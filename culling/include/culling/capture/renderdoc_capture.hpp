#pragma once
// Writing a RenderDoc capture of this process's own Vulkan work (`run
// --renderdoc-capture`, the studio's Culling > Capture in RenderDoc), through
// RenderDoc's in-application API (renderdoc_app.h; Debian: librenderdoc-dev
// for the header, librenderdoc for the library, loaded at run time so that a
// machine without RenderDoc runs everything else). Reading captures is
// capture_reader.hpp's job, in another process: a captured process must not
// replay (docs/RENDERDOC.md).

#include <memory>
#include <string>

namespace lc {

class RenderDocCapture {
public:
    // Loads librenderdoc.so (or LIGHTCULL_RENDERDOC_LIBRARY) into the process
    // and enables its Vulkan layer. Must come before this process creates its
    // first Vulkan instance (the layer is picked at instance creation): throws
    // DeviceError when one was created, or when the library cannot be loaded
    // (one line: which Debian package to install).
    // The capture is written to `path` (atomically, replacing it), titled
    // `title` in RenderDoc.
    RenderDocCapture(const std::string& path, const std::string& title);
    ~RenderDocCapture();
    RenderDocCapture(const RenderDocCapture&) = delete;
    RenderDocCapture& operator=(const RenderDocCapture&) = delete;

    // Starts capturing the Vulkan calls of this process on the device RenderDoc
    // sees as active (the first created).
    void start();
    // A user's culling shader runs on a Vulkan device of its own
    // (custom/custom_cull.hpp): with this set, the capture starts on that
    // device right before its dispatch (startOnInstance) instead of at
    // start(). The capture then holds the shader's inputs as it read them
    // (params, depth image and buffer, lights) and its lists, not the depth
    // pre-pass, which ran on another device. That pass calls finish() after
    // its dispatch, before its device is destroyed.
    void captureCustomShader() { customShader_ = true; }
    bool capturesCustomShader() const { return customShader_; }
    // Starts capturing on the device of this VkInstance, unless a capture runs.
    void startOnInstance(void* vkInstance);
    bool capturing() const;

    // The capture of this process (set while one exists), for the passes
    // that start it on a device of their own.
    static RenderDocCapture* active();
    // Ends the capture and moves the file RenderDoc wrote to the path. Once
    // written, a second call does nothing (a pass that captured a device of
    // its own finishes before that device goes away). Throws DeviceError when
    // nothing was captured or RenderDoc wrote no capture.
    void finish();
    // Ends a started capture without writing it (an error during the work).
    void discard();

    // The in-application API's version, "1.6.0".
    std::string version() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    bool customShader_ = false;
};

// Whether this process has created a Vulkan instance (vk_context counts them):
// RenderDoc must be loaded before the first.
bool vulkanInstanceCreated();

} // namespace lc
