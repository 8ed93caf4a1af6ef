#pragma once
// Bring your own culling (docs/CUSTOM_CULLING.md): run a renderer's own
// culling compute shader (GLSL, HLSL or SPIR-V) on the Vulkan device with
// the inputs the contract fixes, or read a dump of an engine's light lists,
// and turn either into a CullResult that ground truth, the metrics, the
// exports and the overlays judge exactly like a built-in algorithm's.

#include "culling/core/backend.hpp"
#include "culling/core/cull_result.hpp"
#include "culling/core/depth.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/math/projection.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace lc {

// How the lists come back (`--layout`).
enum class ListLayout {
    Fixed,   // fixed:N  per list: a count, then N indices (counts above N are overflow)
    Compact, // compact[:N] one counter, per list offset+count, then an index array of N entries
    Bitmask, // bitmask  per list ceil(lights / 32) words, bit i = light i
};
struct LayoutSpec {
    ListLayout kind = ListLayout::Fixed;
    std::uint32_t capacity = 64; // fixed: indices per list; compact: entries in all (0: 64 per list)
};
// "fixed:64", "compact", "compact:100000", "bitmask". Throws SettingsError("layout", ...).
LayoutSpec parseLayout(const std::string& text);
std::string toString(const LayoutSpec& l);

// Which list a pixel loops over (`--lists`): tile = one list per tile (as
// minmax), halfz = two per tile split at the middle of the tile's min/max
// view depth (as halfz), froxel:N[:log|linear] = N slices of the froxel
// range per tile (as clustered), cells:N[:log|linear] = N cells of the
// tile's own min/max view depth per tile (2.5d's cells, each with a list).
enum class ListKind { Tile, HalfZ, Froxel, Cells };
struct ListSpec {
    ListKind kind = ListKind::Tile;
    std::uint32_t slices = 16;       // froxel, cells: 1..32
    Slicing slicing = Slicing::Log;  // froxel, cells
};
ListSpec parseListSpec(const std::string& text); // throws SettingsError("lists", ...)
std::string toString(const ListSpec& l);

// The output buffer's size in 32-bit words for `lists` lists and `lights` lights.
std::uint64_t layoutWords(const LayoutSpec& layout, std::uint64_t lists, std::uint64_t lights);

struct CustomShaderOptions {
    std::string path;              // .comp/.glsl (GLSL), .hlsl (HLSL), .spv (SPIR-V)
    LayoutSpec layout;
    ListSpec lists;
    std::string entry = "main";
    bool validation = true;        // the Khronos validation layer: user code, on by default
    double timeoutMs = 10000;      // a dispatch still running then is a hang
    std::string device;            // Vulkan device, as for the built-in backend
    std::string headerLayout;      // the layout its settings line states ("": none), a flag overriding it or not
};

// The settings a shader states in a comment of its leading block (comments,
// blank and # lines before the first line of code; a licence header may come
// first): `// lightcull: --layout fixed:64 --lists tile` (`--entry NAME` too);
// flags given by the caller override them. Throws InputError naming the file
// and line for bad settings, a second settings line, or one after code.
void applyShaderHeader(const std::string& shaderText, const std::string& path, CustomShaderOptions& options,
                       bool layoutGiven, bool listsGiven, bool entryGiven);

// A shader file's options: its first-line settings (none for .spv), under
// what the caller sets (a non-empty `layout`, `lists` or `entry` wins, as a
// command-line flag does). Throws InputError naming the file when it cannot
// be read or its first line is bad, SettingsError for a bad `layout`/`lists`.
CustomShaderOptions shaderOptionsFromFile(const std::string& path, const std::string& layout = {},
                                          const std::string& lists = {}, const std::string& entry = {});

// A validation layer message without the object handles and the spec's
// quotation: severity, VUID and what is wrong (any other text as it is).
std::string validationGist(const std::string& message);

// What a custom culling (shader or dump) did beside its lists.
struct CustomCullReport {
    std::string source;                  // the shader or dump file
    std::string layout, lists;           // as given
    std::string headerLayout;            // a shader's settings line's layout, where --layout overrode another
    std::uint64_t overflowLists = 0;     // lists whose count exceeded the layout's capacity
    std::uint64_t overflowEntries = 0;   // entries that did not fit (fixed: count - N summed; compact: past N)
    std::uint64_t invalidIndices = 0;    // indices >= the light count (reported, never followed)
    std::uint64_t duplicateIndices = 0;  // the same light twice in one list (kept once)
    // Which lists (CullResult numbering, ascending) overflowed, and which held
    // an invalid index: a miss in such a list is labelled with that cause;
    // and which held a light twice.
    std::vector<std::uint32_t> overflowedListIds, invalidIndexListIds, duplicateIndexListIds;
    std::vector<std::string> validationMessages; // the validation layer's, during this shader's run
    double passMs = -1;                  // CPU wall time around submit and wait of the dispatch
    std::string device;
    // The built-in algorithm with the same list rule on the CPU backend, for
    // comparison: its entries, and lists where the two differ.
    std::string builtinAlgorithm;
    std::uint64_t builtinEntries = 0, listsDifferingFromBuiltin = 0;
    // What was read but looks wrong without being an error (a dump longer
    // than its layout needs: a padded buffer, or the wrong layout or grid).
    std::vector<std::string> warnings;
};

// Why a list lacks a light its pixels need. A list that overflowed its
// layout's capacity, or that held an index past the light count, is labelled
// by that (the tool cannot tell whether the culling's test would have listed
// the light had there been room); any other miss is the culling's own test.
// A built-in algorithm's engine limits (CullSettings::cap, maxEntries,
// maxLights) label a light they dropped "list full" or "light limit".
enum class MissCause { CullingTest, ListFull, LightLimit, InvalidIndex };
const char* toString(MissCause c); // "culling test", "list full", "light limit", "invalid index"
const char* jsonName(MissCause c); // "culling_test", "list_full", "light_limit", "invalid_index"

// One false negative, located: in `tile`, `pixels` geometry pixels need
// `light` but their list (`list`) does not hold it.
struct MissedLight {
    std::uint32_t tile = 0, list = 0, light = 0, pixels = 0;
    MissCause cause = MissCause::CullingTest;
};
// Every (list, light) pair behind run.truth's false negatives: the culling
// test's misses first (they are the culling's flaws; a full list is a limit),
// then list full, then invalid index; within a cause, most pixels first.
std::vector<MissedLight> locateFalseNegatives(const RunOutput& run, const Projection& proj);

// Decodes raw output words (as `layout` lays them out) into `result`'s lists
// (ascending, unique), counting overflow, invalid and duplicate indices.
// `result` must already hold the grid and list count (listOffset.size()).
void decodeLists(const std::vector<std::uint32_t>& words, const LayoutSpec& layout, std::uint32_t lightCount,
                 CullResult& result, CustomCullReport& report);

// Runs the shader over `depth` on a Vulkan device of its own: compile, bind,
// dispatch one workgroup per tile, read back, decode. The result has the list
// rule of options.lists, tile bounds from the CPU reference, backend
// "custom". Throws InputError (file:line) for compile errors, DeviceError for
// a hang (after options.timeoutMs; the device is then abandoned and the next
// call opens a fresh one) or any failed Vulkan call (that device is closed).
CullResult runCustomShader(const CustomShaderOptions& options, const DepthImage& depth, const Projection& proj,
                           const TileGrid& grid, const ViewLights& lights, CustomCullReport& report);
// What runCustomShader made in this process: Vulkan devices, and pipelines
// (one per distinct SPIR-V and entry point on a device). A finished run
// leaves its device, with the last 32 pipelines made on it, to the next run
// with the same device options: a hunt or report over one shader opens one
// device and compiles each distinct set of defines once.
struct CustomShaderDeviceCount {
    std::uint64_t devicesOpened = 0, pipelinesMade = 0;
};
CustomShaderDeviceCount customShaderDevices();

// A user's culling shader as a list source of the one pipeline
// (core/pipeline.hpp): runCustomShader over the depth it is handed; what the
// shader did beside its lists goes to `report` and RunOutput::custom.
class ShaderLists final : public ListSource {
public:
    ShaderLists(const CustomShaderOptions& options, CustomCullReport& report) : options_(options), report_(report) {}
    CullResult makeLists(const Scene& scene, const DepthImage& depth, const Projection& proj, const TileGrid& grid,
                         const ViewLights& lights) override;
    std::shared_ptr<const CustomCullReport> report() const override;

private:
    CustomShaderOptions options_;
    CustomCullReport& report_;
};

// An engine's dumped lists as a list source (checkListDump's reader).
class DumpLists final : public ListSource {
public:
    DumpLists(std::string path, const LayoutSpec& layout, const ListSpec& lists, CustomCullReport& report)
        : path_(std::move(path)), layout_(layout), lists_(lists), report_(report) {}
    // Words already read (a RenderDoc capture's buffer): `source` names them.
    DumpLists(std::string source, std::vector<std::uint32_t> words, const LayoutSpec& layout, const ListSpec& lists,
              CustomCullReport& report)
        : path_(std::move(source)), words_(std::move(words)), inMemory_(true), layout_(layout), lists_(lists),
          report_(report) {}
    CullResult makeLists(const Scene& scene, const DepthImage& depth, const Projection& proj, const TileGrid& grid,
                         const ViewLights& lights) override;
    std::shared_ptr<const CustomCullReport> report() const override;

private:
    std::string path_;
    std::vector<std::uint32_t> words_;
    bool inMemory_ = false;
    LayoutSpec layout_;
    ListSpec lists_;
    CustomCullReport& report_;
};

// The depth pre-pass, the custom shader, ground truth and (unless off) the
// image error: the one pipeline with ShaderLists; `depthOverride`
// (non-null) replaces the pre-pass with an engine's own depth buffer.
RunOutput runCustomPipeline(const Scene& scene, const CustomShaderOptions& options, CullBackend& depthBackend,
                            const RunOptions& runOptions, CustomCullReport& report,
                            const DepthImage* depthOverride = nullptr);

// An engine's own lists from a file: raw little-endian 32-bit words in
// `layout` (as a GPU debugger's buffer export writes them), or CSV with one
// line per list "list,light,light,..." (a header line is allowed). Judged on
// `depth` like a shader's output: the one pipeline with DumpLists, shaded
// (when asked) on the CPU reference.
RunOutput checkListDump(const Scene& scene, const std::string& listsPath, const LayoutSpec& layout,
                        const ListSpec& lists, const DepthImage& depth, const RunOptions& runOptions,
                        CustomCullReport& report);

// An engine's depth buffer: raw float32 window depth (width x height, row 0
// at the top) or a 16-bit greyscale PNG (0..65535 -> 0..1), in the scene
// camera's depth convention. Throws InputError naming the file.
DepthImage loadDepthFile(const std::string& path, const Projection& proj);

} // namespace lc
