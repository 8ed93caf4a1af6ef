#pragma once
// Reading a RenderDoc capture of a renderer's frame (`lightcull capture-info`,
// `check --capture`, the studio's File > Open RenderDoc capture). RenderDoc's
// replay runs in a helper process (src/capture/replay.py, with the system
// python3 and Debian's python3-renderdoc): a process that captured must not
// replay, and a replay that crashes or hangs on a hostile file takes only
// that process with it. This side parses what the helper prints and the
// bytes it writes (docs/RENDERDOC.md).

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace lc {

// A dispatch, draw, copy or clear of the capture.
struct CaptureAction {
    std::uint32_t event = 0;
    std::string name;                 // "vkCmdDispatch()"
    std::string kind;                 // dispatch, draw, copy, clear
    std::vector<std::string> markers; // the debug marker regions it lies in, outermost first
    std::array<std::uint32_t, 3> dims{}; // a dispatch's workgroups
    std::string markerPath() const;   // "outer / inner", empty when none
};

// One descriptor of the compute pipeline bound at an event.
struct CaptureBinding {
    std::uint32_t set = 0, binding = 0, element = 0;
    std::string kind;       // buffer, image, other
    std::string descriptor; // RenderDoc's descriptor type (ReadWriteBuffer, ConstantBuffer, ImageSampler, ...)
    std::string resource;   // the resource's debug name (RenderDoc's name when it has none)
    std::string variable;   // the shader's name for it, when the shader has debug names
    std::uint64_t offset = 0, size = 0, length = 0; // buffer: the bound range, the whole buffer
    std::uint32_t width = 0, height = 0, samples = 1; // image
    std::string format;     // image: "R32_FLOAT", "D32", "D24S8", ...
    std::uint32_t componentBytes = 0, components = 0;
    std::string componentType; // Float, UNorm, Depth, UInt, ...
    std::string where() const; // "set 0 binding 3 (LcLights_var, lc.custom.lights)"
};

struct CaptureInfo {
    std::string file;
    std::string renderdoc; // the replaying RenderDoc's version
    std::vector<CaptureAction> actions;
    std::uint32_t event = 0; // the event bindings were read at (0: none)
    std::vector<CaptureBinding> bindings;
};

// A binding's bytes after the event: a buffer's bound range, an image's
// first mip and layer as RenderDoc packs it.
struct CaptureBlob {
    CaptureBinding binding;
    std::string bytes;
};

// The capture's actions, and with `event` > 0 the compute bindings at that
// event. Throws InputError naming the file (not a capture, another API's, an
// event that is no action of it), DeviceError when RenderDoc's Python module
// or python3 is missing (one line: what to install) or the replay crashed or
// ran past its time limit (LIGHTCULL_REPLAY_TIMEOUT_S, default 300 s).
CaptureInfo readCaptureInfo(const std::string& capture, std::uint32_t event = 0);

// readCaptureInfo at the dispatch `what` names (findDispatch), in one replay.
CaptureInfo readDispatchInfo(const std::string& capture, const std::string& what);
// The event `what` names: a number (a dispatch's event id), or text found in
// one dispatch's name or marker path ("cull", "Light culling"). Throws
// InputError naming the file when none or several dispatches match (listing
// them).
std::uint32_t findDispatch(const CaptureInfo& info, const std::string& what);

// The bytes of each binding `specs` names (key -> "SET.BINDING" or a
// resource's or shader variable's name) after dispatch `event`.
std::map<std::string, CaptureBlob> readCaptureBindings(const std::string& capture, std::uint32_t event,
                                                       const std::map<std::string, std::string>& specs);
// readCaptureInfo + findDispatch + readCaptureBindings in one replay (opening
// a large capture takes seconds): `event` gets the dispatch's event id.
// Throws as findDispatch does when `dispatch` names none or several.
std::map<std::string, CaptureBlob> readDispatchBindings(const std::string& capture, const std::string& dispatch,
                                                        const std::map<std::string, std::string>& specs,
                                                        std::uint32_t& event);

} // namespace lc
