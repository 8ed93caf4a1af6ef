#pragma once
// A renderer's culling dispatch, read from a RenderDoc capture and turned
// into what `check` judges: the lights and camera as a Scene, the depth the
// culling read, and the lists in a layout decodeLists reads. The renderer's
// own light struct, camera constants and list layout are given by a short
// JSON description (docs/RENDERDOC.md), and every field read is echoed so a
// wrong description shows at once.

#include "culling/capture/capture_reader.hpp"
#include "culling/core/depth.hpp"
#include "culling/custom/custom_cull.hpp"
#include "culling/scene/scene.hpp"

#include <optional>
#include <string>
#include <vector>

namespace lc {

// Where a value lives: a binding ("SET.BINDING" or a name) and a byte offset.
struct CaptureField {
    std::string binding;
    std::uint32_t offset = 0;
};

struct CaptureDescription {
    std::string file; // the description's file, for errors

    // lights: `count` structs of `stride` bytes from the binding's range.
    std::string lights;
    std::uint32_t lightStride = 16;
    std::optional<std::uint32_t> lightCount;       // a number given
    std::optional<CaptureField> lightCountField;   // a uint32 in the capture
    std::uint32_t positionOffset = 0, radiusOffset = 12; // vec3, float
    bool lightsInViewSpace = true;
    std::optional<std::uint32_t> spotAxisOffset, spotAngleOffset; // vec3, float
    enum class AngleUnit { Radians, Degrees, Cosine } spotAngleUnit = AngleUnit::Radians;

    // camera: matrices in a buffer, or the lens given.
    std::optional<CaptureField> projection, view; // column-major mat4 (row-major with `rowMajor`)
    bool rowMajor = false;
    std::optional<double> fovYDeg, nearPlane, farPlane; // farPlane: +inf for infinite
    bool reversed = false;

    // depth: an image, or a float32 buffer of width x height.
    std::string depth;
    std::uint32_t depthWidth = 0, depthHeight = 0;
    bool bottomUp = false; // row 0 at the bottom

    // lists
    enum class Lists { Contract, CountsIndices, Ranges, Pairs, ZBin } listKind = Lists::Contract;
    LayoutSpec layout;                // Contract: fixed:N, compact[:N], bitmask; CountsIndices: N in capacity
    std::string listBuffer;           // Contract
    std::string counts, indices, offsets, ranges; // the other kinds
    // ZBin (Drobot 2017): a light bit mask per tile (`masks`) and a range
    // of sorted light positions per depth bin (`bins`, lo <= hi; lo > hi:
    // empty), the bins linear in view depth over [binNear, binFar] (the
    // camera's near and far unless given); `order` (optional) names the
    // light at each sorted position, else the light buffer is in that order.
    std::string masks, bins, order;
    bool binsU16 = false; // lo | hi << 16 in one word; else two words
    std::optional<std::uint32_t> binCount;
    std::optional<double> binNear, binFar;
    ListSpec rule;
    std::uint32_t tileSize = 16;
};

// Parses a description. Throws InputError naming the file and the JSON path
// of a missing, mistyped, overlapping or out-of-range field.
CaptureDescription parseCaptureDescription(const std::string& text, const std::string& file);
CaptureDescription loadCaptureDescription(const std::string& path);

// The bindings a description reads: key -> spec, for readCaptureBindings.
std::map<std::string, std::string> captureBindingsNeeded(const CaptureDescription& d);

// A Z-binned frame's bins (CaptureDescription::Lists::ZBin).
struct CaptureZBin {
    std::vector<std::uint32_t> order, lo, hi; // order[k]: the light at sorted position k
    double near = 0, far = 0;                 // the bins' view depth range
};

struct CaptureFrame {
    Scene scene;        // the capture's lights and camera (view space: the camera at the origin looking down -Z)
    DepthImage depth;
    std::vector<std::uint32_t> words; // the lists in `layout`
    LayoutSpec layout;
    std::string layoutName;           // the description's: "counts+indices:32", "ranges", "fixed:64", ...
    ListSpec rule;
    std::string source;               // "frame.rdc event 13"
    std::vector<std::string> echo;    // every field read, one line each
    // A Z-binned frame: `words` are its tile masks (bitmask, bits by light
    // index); a pixel's lights are its tile's within its bin's range.
    std::optional<CaptureZBin> zbin;
    std::vector<std::string> warnings;
};

// Decodes the bytes read. Throws InputError naming the capture (and the
// binding, light or field) when a buffer is smaller than the description
// needs or a value makes no light, camera or depth.
CaptureFrame decodeCaptureFrame(const CaptureDescription& d, const std::map<std::string, CaptureBlob>& blobs,
                                const std::string& capture, std::uint32_t event);

// readCaptureInfo + findDispatch + readCaptureBindings + decodeCaptureFrame.
CaptureFrame loadCaptureFrame(const std::string& capture, const std::string& dispatch,
                              const CaptureDescription& description);

// A run's depth taken from a capture: RunOutput::depthFrom says so
// ("capture frame.rdc event 13"), and what reads a run (the studio's status,
// Explain) asks captureDepth() instead of parsing that text.
std::string captureDepthSource(const CaptureFrame& frame);
bool captureDepth(const RunOutput& run);

// The capture's lists judged like a dump: the one pipeline with the lists
// from the frame, on the frame's depth. `scene` (non-null) stands for the
// frame's: the studio's edited lights judged against the capture's lists
// (its camera must be the frame's, or the depth is another view's).
RunOutput checkCaptureFrame(const CaptureFrame& frame, const RunOptions& runOptions, CustomCullReport& report,
                            const Scene* scene = nullptr);

} // namespace lc
