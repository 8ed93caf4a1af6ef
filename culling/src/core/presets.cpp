// Engine presets (presets.hpp). Sources and what each model leaves out:
// docs/ENGINES.md, which cites the file and commit every number was read at.
#include "culling/core/presets.hpp"

#include "culling/core/errors.hpp"

#include <algorithm>
#include <cmath>

namespace lc {

namespace {

std::uint32_t ceilDiv(std::uint64_t a, std::uint64_t b) { return std::uint32_t((a + b - 1) / b); }

// Unity URP Forward+ (ForwardLights.cs): words per tile from the visible
// lights, the tile width doubled from 8 until the tile masks fit the word
// budget, the Z bins from the bin budget (4096 words) over (2 + words) per bin.
void deriveUrp(CullSettings& s, Camera& c, std::size_t lights) {
    const std::uint64_t visible = s.maxLights ? std::min<std::uint64_t>(lights, s.maxLights) : lights;
    // UniversalRenderPipeline.maxTileWords: 1024 vec4s with at most 32 lights, else 4096.
    const std::uint64_t maxTileWords = s.maxLights && s.maxLights <= 32 ? 4096 : 16384;
    const std::uint64_t words = std::max<std::uint64_t>(1, (visible + 31) / 32);
    std::uint32_t tile = 8;
    while (std::uint64_t(ceilDiv(c.width, tile)) * ceilDiv(c.height, tile) * words > maxTileWords && tile < 256)
        tile *= 2;
    c.tileSize = tile;
    s.bins = std::uint32_t(std::clamp<std::uint64_t>(4096 / (2 + words), 1, 16384));
}

// Filament (Froxelizer.cpp): 4096 froxels (a 16 KiB uniform buffer) over 16
// slices, square froxels whose side is a multiple of 8 pixels.
void deriveFilament(CullSettings&, Camera& c, std::size_t) {
    const double perSlice = 4096.0 / 16.0;
    const double side = std::sqrt(double(c.width) * double(c.height) / perSlice);
    std::uint32_t t = std::max<std::uint32_t>(8, std::uint32_t(std::ceil(side / 8.0)) * 8);
    while (std::uint64_t(ceilDiv(c.width, t)) * ceilDiv(c.height, t) > std::uint64_t(perSlice) && t < 256) t += 8;
    c.tileSize = std::min<std::uint32_t>(t, 256);
}

// Bevy (cluster/mod.rs): 4096 clusters over 24 slices, square in screen
// space: per layer 4096 / 24, y = sqrt(per layer / aspect), x = per layer / y.
void deriveBevy(CullSettings&, Camera& c, std::size_t) {
    const double perLayer = 4096.0 / 24.0;
    const double aspect = double(c.width) / double(c.height);
    const double y = std::max(1.0, std::floor(std::sqrt(perLayer / aspect)));
    const double x = std::max(1.0, std::floor(perLayer / y));
    const std::uint32_t t = std::uint32_t(std::ceil(std::max(double(c.width) / x, double(c.height) / y)));
    c.tileSize = std::clamp<std::uint32_t>(t, 1, 256);
}

// Unreal (LightGridInjection.cpp): with linked-list culling, a pool of
// cells x MaxCulledLightsPerCell (32) entries shared by every cell.
void deriveUnreal(CullSettings& s, Camera& c, std::size_t) {
    const std::uint64_t cells = std::uint64_t(ceilDiv(c.width, c.tileSize)) * ceilDiv(c.height, c.tileSize) * s.cells;
    s.maxEntries = std::uint32_t(std::min<std::uint64_t>(cells * 32, 100000000));
}

// Each preset: name, engine, settings, the grid it derives (and how), what
// it leaves out, and how far the engine lets each limit go (the setting or
// constant that sets it, cited in docs/ENGINES.md; 0: no fixed maximum).
std::vector<EnginePreset> buildPresets() {
    std::vector<EnginePreset> p;
    p.push_back({"urp",
                 "Unity URP Forward+ (desktop)",
                 {{"algorithm", "zbin"}, {"max-lights", "256"}, {"limit-keep", "nearest"}},
                 deriveUrp,
                 "tile: 8 px doubled until tiles x ceil(lights/32) words <= 16384; bins: 4096 / (2 + words per tile)",
                 "URP's Z bins are log2 in perspective (ours linear); reflection probes share the tile masks; "
                 "directional lights are not binned",
                 {{"max-lights", 256, "URP's k_MaxVisibleLightCountDesktop"}}});
    p.push_back({"urp-mobile",
                 "Unity URP Forward+ (mobile, OpenGL, WebGPU)",
                 {{"algorithm", "zbin"}, {"max-lights", "32"}, {"limit-keep", "nearest"}},
                 deriveUrp,
                 "tile: 8 px doubled until tiles x ceil(lights/32) words <= 4096; bins: 4096 / (2 + words per tile)",
                 "as urp; GLES 3.0 and older keep 16 lights",
                 {{"max-lights", 32, "URP's k_MaxVisibleLightCountMobile"}}});
    p.push_back({"hdrp-fptl",
                 "Unity HDRP fine-pruned tiles (FPTL)",
                 {{"algorithm", "fptl"}, {"tile", "16"}, {"cap", "63"}, {"overflow-policy", "index"}, {"max-lights", "512"},
                  {"limit-keep", "index"}},
                 nullptr,
                 "",
                 "the coarse list of 64 is filled in GPU atomic order before pruning (not modelled); caps are per "
                 "light category; which lights HDRP keeps past 512 on screen was not found (modelled by index)",
                 {{"cap", 63, "ShaderConfig FPTLMaxLightCount"}, {"max-lights", 2048, "the HDRP asset's maximum punctual lights on screen"}}});
    p.push_back({"hdrp-cluster",
                 "Unity HDRP clustered",
                 {{"algorithm", "clustered"}, {"tile", "32"}, {"cells", "32"}, {"slicing", "log"}, {"cap", "63"},
                  {"overflow-policy", "index"}, {"max-lights", "512"}, {"limit-keep", "index"}},
                 nullptr,
                 "",
                 "HDRP has 64 slices with a per-tile log base fitted to the tile's depth (ours: 32 log slices over "
                 "the camera range); the coarse list of 128 is filled in GPU atomic order",
                 {{"cap", 63, "the cluster count's 6 bits"}, {"max-lights", 2048, "the HDRP asset's maximum punctual lights on screen"}}});
    p.push_back({"unreal-5",
                 "Unreal Engine 5 forward light grid (linked-list culling, the default)",
                 {{"algorithm", "clustered"}, {"tile", "64"}, {"cells", "32"}, {"slicing", "log"},
                  {"overflow-policy", "index"}},
                 deriveUnreal,
                 "max-entries: grid cells (64 px x 32 slices) x 32, one pool for every cell",
                 "Unreal's slices are log2(z*B + O)*S with a near offset and a reserved last slice (ours: log over "
                 "the camera range); HZB cell culling",
                 {{"max-entries", 0, "r.Forward.MaxCulledLightsPerCell (the pool is cells x it)"}}});
    p.push_back({"unreal-5-fixed",
                 "Unreal Engine 5 forward light grid, r.Forward.LightLinkedListCulling 0",
                 {{"algorithm", "clustered"}, {"tile", "64"}, {"cells", "32"}, {"slicing", "log"}, {"cap", "32"},
                  {"overflow-policy", "index"}},
                 nullptr,
                 "",
                 "as unreal-5",
                 {{"cap", 0, "r.Forward.MaxCulledLightsPerCell"}}});
    p.push_back({"godot-4",
                 "Godot 4 clustered forward",
                 {{"algorithm", "raster"}, {"proxy-depth", "slices"}, {"proxy-level", "1"}, {"proxy-segments", "32"},
                  {"proxy-cone-angle", "60"}, {"tile", "32"}, {"cells", "32"}, {"slicing", "linear"},
                  {"skip-empty", "false"}, {"max-lights", "512"}, {"limit-keep", "index"}},
                 nullptr,
                 "",
                 "Godot samples its proxies at several pixels per cluster (modelled by exact overlap; --conservative "
                 "false is one sample per tile) and takes one depth bit per fragment (modelled by the triangle's "
                 "depths over the tile); its 32 depth bits span 0..far (ours near..far); 512 is per element type "
                 "(omni, spot), ours for all lights together",
                 {{"max-lights", 8192, "rendering/limits/cluster_builder/max_clustered_elements"}}});
    p.push_back({"filament",
                 "Filament froxels",
                 {{"algorithm", "clustered"}, {"cells", "16"}, {"slicing", "log"}, {"max-lights", "256"}, {"limit-keep", "index"}, {"max-entries", "65535"},
                  {"overflow-policy", "all-lights"}},
                 deriveFilament,
                 "tile: square froxels, side a multiple of 8 px, at most 4096 / 16 per slice",
                 "Filament's slice 0 is 0..5 m and slices 1..15 log to 100 m (ours: log over the camera range); "
                 "records are shared with a left or upper neighbour; its count clamp of 255 per froxel (reached only "
                 "with all 256 lights in one froxel) is not modelled; which lights it keeps past 256 was not read",
                 {{"max-lights", 256, "CONFIG_MAX_LIGHT_COUNT"}, {"max-entries", 65535, "the record buffer (16-bit offsets)"}}});
    p.push_back({"bevy",
                 "Bevy clustered forward (storage buffers)",
                 {{"algorithm", "clustered"}, {"cells", "24"}, {"slicing", "log"}},
                 deriveBevy,
                 "tile: 4096 clusters over 24 slices, square in screen space",
                 "Bevy's first slice is near..5 and its far plane the farthest light's range (ours: log over the "
                 "camera range); dynamic resizing shrinks the grid before an index list overflows",
                 {}});
    p.push_back({"bevy-webgl2",
                 "Bevy clustered forward (WebGL2 uniform buffers)",
                 {{"algorithm", "clustered"}, {"cells", "24"}, {"slicing", "log"}, {"max-lights", "204"},
                  {"limit-keep", "index"}, {"max-entries", "16384"}, {"overflow-policy", "index"}},
                 deriveBevy,
                 "tile: as bevy; 204 objects and 16384 indices in all",
                 "as bevy; the order Bevy keeps objects in past 204 was not verified (modelled by index)",
                 {{"max-lights", 204, "MAX_UNIFORM_BUFFER_CLUSTERABLE_OBJECTS"}, {"max-entries", 16384, "ViewClusterBindings::MAX_INDICES"}}});
    p.push_back({"threejs",
                 "three.js TiledLightsNode (WebGPU renderer)",
                 {{"algorithm", "naive"}, {"tile", "32"}, {"cap", "8"}, {"overflow-policy", "index"},
                  {"max-lights", "1024"}, {"limit-keep", "index"}},
                 nullptr,
                 "",
                 "three.js tiles have no depth at all and test a screen-space circle against the tile (ours: the "
                 "tile's side planes with the camera's near and far); spot lights are not tiled there",
                 {{"cap", 0, "TiledLightsNode's tileLightCount"}, {"max-lights", 0, "TiledLightsNode's maxLights (its constructor's first argument)"}}});
    return p;
}

} // namespace

const EnginePreset::Room* EnginePreset::roomFor(const std::string& param) const {
    for (const Room& r : room)
        if (r.param == param) return &r;
    return nullptr;
}

const std::vector<EnginePreset>& enginePresets() {
    static const std::vector<EnginePreset> presets = buildPresets();
    return presets;
}

const EnginePreset& enginePreset(const std::string& name) {
    std::string known;
    for (const EnginePreset& p : enginePresets()) {
        if (p.name == name) return p;
        known += (known.empty() ? "" : ", ") + p.name;
    }
    throw SettingsError("preset", "unknown preset '" + name + "' (known: " + known + ")");
}

void applyPreset(const EnginePreset& preset, CullSettings& settings, Camera& camera, std::size_t lightCount,
                 const std::vector<std::pair<std::string, std::string>>& overrides) {
    // From the defaults, so that nothing of an earlier choice stays.
    CullSettings s;
    Camera c = camera;
    c.tileSize = 16;
    for (const auto& [name, value] : preset.params) setParam(s, c, name, value);
    for (const auto& [name, value] : overrides) setParam(s, c, name, value);
    if (preset.derive) preset.derive(s, c, lightCount);
    for (const auto& [name, value] : overrides) setParam(s, c, name, value);
    settings = s;
    camera.tileSize = c.tileSize;
}

const EnginePreset* presetMatching(const CullSettings& settings, const Camera& camera, std::size_t lightCount) {
    for (const EnginePreset& p : enginePresets()) {
        CullSettings s;
        Camera c = camera;
        applyPreset(p, s, c, lightCount);
        bool same = c.tileSize == camera.tileSize;
        for (const ParamSpec& spec : cullParams())
            same = same && getParam(s, c, spec.name) == getParam(settings, camera, spec.name);
        if (same) return &p;
    }
    return nullptr;
}

} // namespace lc
