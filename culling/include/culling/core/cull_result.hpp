#pragma once
// The output of a culling pass, from either backend.

#include "culling/core/params.hpp"
#include "culling/math/tile_math.hpp"

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace lc {

struct DepthImage;
class Projection;

// Per-phase wall or device times in milliseconds; negative = not run.
struct Timings {
    double depthMs = -1, cullMs = -1, groundTruthMs = -1, shadeMs = -1;
};

// What the engine limits (CullSettings::cap, maxLights, maxEntries) took from
// the lists the culling test made (applyListLimits, core/limits.hpp). Empty
// when no limit applies. List ids are the result's own numbering.
struct ListLimits {
    // Per light: 1 when the light is past the per-view light limit (so in
    // no list); empty when maxLights is 0 or not reached.
    std::vector<std::uint8_t> overLightLimit;
    std::uint64_t lightsOverLimit = 0;
    // Lists that held more lights than the cap (or than the record buffer
    // had left), ascending; per such list k the lights the limit dropped are
    // droppedLights[droppedOffset[k] .. droppedOffset[k+1]), ascending (none
    // under the all-lights fallback, which lists every light instead).
    std::vector<std::uint32_t> overflowLists, droppedOffset, droppedLights;
    // The longest list the test made (of the lights the light limit keeps:
    // the others are never tested), before any cap: the smallest cap that
    // never overflows.
    std::uint32_t longestUncapped = 0;
    // Entries before the cap and record buffer; the lists' entries after
    // them are entries().
    std::uint64_t entriesUncapped = 0;

    bool empty() const { return overLightLimit.empty() && overflowLists.empty(); }
    bool isOverLimit(std::uint32_t light) const { return light < overLightLimit.size() && overLightLimit[light]; }
    // Index into overflowLists of `list`, or -1 when it did not overflow.
    long overflowIndex(std::uint32_t list) const;
    // The lights the limits dropped from `list` (empty when it did not overflow).
    std::pair<const std::uint32_t*, const std::uint32_t*> droppedFrom(std::uint32_t list) const;
    bool dropped(std::uint32_t list, std::uint32_t light) const;
};

// Lists stored compactly: list l covers lightIndices[listOffset[l] ..
// listOffset[l] + listCount[l]), indices ascending. Memory grows with the
// entries the scene produces: 4 bytes per entry + 8 per list + per-tile depth
// bounds, never tiles x lights.
//
// List numbering: `all` has exactly one list. Every other algorithm has
// listsPerTile lists per tile, list = tileIndex * listsPerTile + sub, where sub
// is 0 (naive, minmax, 2.5d), 0 near / 1 far (halfz), or the depth slice
// (clustered; 2.5d with cellLists: the cell of the tile's depth range).
struct CullResult {
    Algorithm algorithm = Algorithm::All;
    CullSettings settings;
    TileGrid grid;
    std::uint32_t listsPerTile = 1;

    // Per tile, view depth bounds of the pixels holding geometry. An empty tile
    // has depthMin = +inf, depthMax = -inf (and, for all but `all`, an empty list).
    // For `halfz`, halfzSplit[t] is the split: depth <= split -> near list.
    std::vector<double> tileDepthMin, tileDepthMax, halfzSplit;
    // Per tile: 2.5d occupancy mask of the cells over [depthMin, depthMax];
    // clustered: occupied slices. Empty otherwise.
    std::vector<std::uint32_t> cellMask;
    // Clustered depth range: slices are `settings.slicing` over [clusterNear, clusterFar].
    double clusterNear = 0, clusterFar = 0;
    // The camera's depth range naive and zbin's masks were culled over (the
    // infinite-far rule applied: CullFrame::cameraFar).
    double cameraNear = 0, cameraFar = 0;
    // zbin (docs/ALGORITHMS.md): the list of a tile is its screen-space light
    // mask (the lights whose culling sphere passes the tile's side planes,
    // with the camera's near and far: naive's test), stored as light indices.
    // The lights sorted by the view depth of their culling sphere's centre
    // (ties by index): zbinOrder[k] is the light at sorted position k,
    // zbinRank[l] the position of light l. Bin b of settings.bins linear bins
    // over [zbinNear, zbinFar] holds the lowest (zbinLo[b]) and highest
    // (zbinHi[b]) sorted position of a light whose depth range reaches it;
    // an empty bin has zbinLo > zbinHi. A pixel in bin b loops over the
    // lights of its tile's mask whose rank lies in [zbinLo[b], zbinHi[b]].
    std::vector<std::uint32_t> zbinOrder, zbinRank, zbinLo, zbinHi;
    double zbinNear = 0, zbinFar = 0;
    // A list per pixel chosen explicitly (row-major, kNoList where no
    // geometry): set only on the per-pixel lists zbinPixelLists() builds.
    std::vector<std::uint32_t> pixelList;

    // 2.5d only (custom culling's `cells:N` rule, docs/CUSTOM_CULLING.md):
    // one list per cell, settings.cells cells (settings.slicing) of the
    // tile's [depthMin, depthMax], instead of one list per tile.
    bool cellLists = false;

    std::vector<std::uint32_t> listOffset, listCount, lightIndices;
    // What the engine limits dropped (settings.cap, maxLights, maxEntries).
    ListLimits limits;

    // Light-versus-volume tests one pass over the lists performed (Vulkan: the
    // candidates left by the light bins; cpu: the lights whose screen bounds
    // reach the tile, per tile, half or froxel); 0 when nothing was tested.
    std::uint64_t volumeTests = 0;

    std::string backend;      // "cpu" or "vulkan"
    std::string device;       // physical device name, or the CPU's
    std::string timingMethod; // how cullMs/depthMs were taken
    // raster: how a proxy's tiles were found (the CPU's exact overlap, the
    // GPU's conservative rasterisation or the edges pushed out in its vertex
    // shader, and why); empty for the other algorithms.
    std::string coverage;
    Timings timings;
    // The depth pre-pass that made the depth this cull read (runPipeline): the
    // scene's triangles and those it rasterised (the Vulkan backend leaves out
    // faces of closed solids turned away from the camera); 0 and 0 where the
    // depth was reused or came from elsewhere.
    std::size_t depthTriangles = 0, depthTrianglesDrawn = 0;

    // The algorithm whose list layout this is: `clustered` for raster with
    // proxy-depth slices (its lists are clusters), else the algorithm.
    Algorithm layout() const { return settings.clusterLists() ? Algorithm::Clustered : algorithm; }
    std::uint32_t listCountTotal() const { return std::uint32_t(listCount.size()); }
    // The lists of a tile as [first, first + count); for `all`, the one list
    // every tile shares.
    std::pair<std::uint32_t, std::uint32_t> tileLists(std::uint32_t tile) const;
    // The list of `tile` that `sub` names (halfz 0/1, clustered slice, cell),
    // or the tile's one list when sub < 0. Throws SettingsError for an index
    // out of range or a missing sub where a tile has several lists.
    std::uint32_t listOf(std::uint32_t tile, int sub = -1) const;
    // The tile a list belongs to (0 for `all`).
    std::uint32_t tileOfList(std::uint32_t list) const;
    // The sub (listOf's) of a list within its tile, or -1 where a tile has
    // one list: what explain's --cell takes.
    int cellOfList(std::uint32_t list) const;
    std::uint64_t entries() const { return lightIndices.size(); }
    // Bytes of the light lists in the form a renderer uploads and reads while
    // shading: 4 per index and 8 per list (offset + count). halfz packs a
    // tile's two adjacent lists as offset, near count, far count and split (16
    // bytes per tile = 8 per list); clustered adds its depth range (8 bytes).
    // So bytes() <= 4 * entries + 8 * lists + 8. The per-tile depth bounds and
    // masks the culling computes on the way are in diagnosticBytes().
    // zbin: the renderer's form instead, a 32-bit range per bin and a bit per
    // light per tile: 4 x bins + 4 x tiles x ceil(lights / 32).
    // With a per-list cap (settings.cap), what an engine with that cap
    // allocates instead: per list a count and `cap` indices, 4 x (cap + 1)
    // bytes, whatever the lists hold (zbin's masks keep their size); with a
    // record buffer (settings.maxEntries) 4 bytes per record it can hold and
    // 8 per list (offset + count).
    std::uint64_t bytes() const;
    // Bytes of the per-tile intermediates kept for diagnostics and overlays,
    // at the GPU's float precision: depth min/max (8 per tile) and cell/slice
    // masks (4 per tile where the algorithm has them).
    std::uint64_t diagnosticBytes() const;
    // The list a shading pass loops over at pixel (px, py) whose geometry lies
    // at view depth viewDepth. Follows exactly the rule the passes use.
    std::uint32_t listOfPixel(std::uint32_t px, std::uint32_t py, double viewDepth) const;
    // zbin: the bin of view depth d (clamped to the bins).
    std::uint32_t zbinOf(double viewDepth) const;
    // Empty when internally consistent (sizes, offsets in range, sorted, unique).
    std::string validate(std::size_t lightCount) const;
};

// The locators of a clustered or 2.5d result's `cells` depth slices: one over
// [clusterNear, clusterFar] for clustered, one per tile over the tile's depth
// bounds for 2.5d (the ranges listOfPixel and the cell masks slice). Empty for
// another algorithm.
std::vector<SliceLocator> cellSlices(const CullResult& r, std::uint32_t cells);

// CullResult::listOfPixel for every pixel of one result: the depth slices'
// boundaries (clustered's one range, 2.5d's per tile) worked out once, the
// same list bit for bit. The result must outlive it.
class PixelListLookup {
public:
    explicit PixelListLookup(const CullResult& result);
    std::uint32_t operator()(std::uint32_t px, std::uint32_t py, double viewDepth) const;

private:
    const CullResult& r_;
    std::vector<SliceLocator> slices_; // clustered: one; 2.5d with cell lists: one per tile
};

// The per-pixel lists a zbin result stands for: one list per (tile, bin)
// some geometry pixel falls in, holding the tile mask's lights whose rank is
// in that bin's range (ascending index), with pixelList naming each pixel's.
// The ground truth and the shading passes judge zbin through these. Any other
// result is returned as is (a copy).
CullResult zbinPixelLists(const CullResult& zbin, const DepthImage& depth, const Projection& proj);

// Sorts lights for zbin: by view depth of the culling sphere's centre, ties by index.
void zbinSortLights(const std::vector<double>& centreDepth, std::vector<std::uint32_t>& order,
                    std::vector<std::uint32_t>& rank);

} // namespace lc
