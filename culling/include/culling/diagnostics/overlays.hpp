#pragma once
// Inspection overlay geometry and the overlays.vtm export: what the studio
// draws in 3D and what ParaView reads, as pure functions of a finished run.
//
// Everything is built from the same plane and slice functions the culling
// passes use (tile_math.hpp): a tile frustum is makeFrustumChunk of the
// tile's rectangle, a cell boundary is sliceBoundary, a light's cell range is
// sliceRangeMask. So a test can check an overlay against the numbers the
// culling actually used. Geometry is in view space (double precision);
// worldFromView() converts.

#include "culling/core/pipeline.hpp"

#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace lc {

// World space from the culling camera's view space.
glm::dmat4 worldFromView(const Camera& camera);

// The frustum a tile's lists were culled against, truncated in depth:
// naive, zbin (its mask) and all: the result's cameraNear..cameraFar; minmax, halfz, 2.5d and
// clustered: the tile's geometry min..max view depth. nullopt for a tile
// without geometry (except naive/all, whose range does not depend on it).
std::optional<FrustumChunk> tileFrustum(const CullResult& r, const Projection& proj,
                                        const ViewLights& lights, std::uint32_t tile);

// One depth cell of a tile, near to far.
struct DepthCell {
    std::uint32_t cell = 0; // 0 = nearest
    std::uint32_t list = 0; // the list (CullResult numbering) a pixel in the cell loops over
    bool occupied = false;  // geometry lies in it
    FrustumChunk chunk;     // the tile's side planes cut at the cell's depth bounds
};
// The depth cells of a tile:
// - 2.5d: settings.cells slabs of [depthMin, depthMax] split by settings.slicing
//   (sliceBoundary), occupancy from cellMask; all serve the tile's one list.
// - halfz: [depthMin, split] (list 2t) and [split, depthMax] (list 2t+1); both
//   hold geometry (min and max pixels lie on either side of the midpoint).
// - clustered: the froxels of the tile's column: settings.cells slices of
//   [clusterNear, clusterFar], occupancy from cellMask, list t*cells + k; also
//   for a tile without geometry (all cells empty then).
// - zbin: the Z-bins the tile's depth range spans, in at most 32 cells of
//   consecutive bins (cell k: its bins' depth range), all serving the mask.
// - naive, minmax, fptl, all: no cells. 2.5d, halfz and zbin tiles without
//   geometry: none.
std::vector<DepthCell> tileCells(const CullResult& r, const Projection& proj, std::uint32_t tile);

// zbin: the slab of the whole camera frustum over the bins light `light`'s
// culling sphere spans (from its first bin's near boundary to its last bin's
// far one); nullopt for other algorithms or a light that reaches no bin.
std::optional<FrustumChunk> zbinLightSlab(const CullResult& r, const Projection& proj, const ViewLights& lights,
                                          std::uint32_t light);

// The cells of `tile` (as bits in tileCells' order) whose depth interval a
// light's sphere (view-space centre, radius) reaches: sliceRangeMask of the
// interval [depth - radius, depth + radius] over the tile's (2.5d) or the
// cluster (clustered) range; halfz: bit 0 when it reaches [min, split], bit 1
// when it reaches [split, max]. Depth only: the passes add the side planes.
// 0 for algorithms without cells and tiles without cells.
std::uint32_t lightCellRange(const CullResult& r, std::uint32_t tile, const glm::dvec3& centerView,
                             double radius);

// Reverse look-up: the lists (ascending) holding light `light`, and the tiles
// (ascending) with at least one such list; for `all`, every tile.
std::vector<std::uint32_t> listsHoldingLight(const CullResult& r, std::uint32_t light);
std::vector<std::uint32_t> tilesHoldingLight(const CullResult& r, std::uint32_t light);

// The tile inspector's rows: for each list of the tile (or only the list of
// cell `cell` for halfz and clustered), every listed light with the number of
// the list's pixels that need it (the ground truth's rule, via
// pixelsNeedingLights) and a verdict, followed by every light some pixel of
// the list needs that the list lacks (Missing: a false negative). For 2.5d a
// cell >= 0 restricts the pixels to those whose depth lies in that cell.
// `all`'s one list serves the whole image: its pixels are the image's, whatever
// the tile. Pixels count only where they hold geometry.
enum class Verdict { Needed, FalsePositive, Missing };
const char* toString(Verdict v); // "needed", "false positive", "MISSING"
struct TileLightRow {
    std::uint32_t list = 0, light = 0;
    std::uint32_t pixelsNeeding = 0;
    Verdict verdict = Verdict::Needed;
};
std::vector<TileLightRow> tileLightRows(const RunOutput& run, const Projection& proj, std::uint32_t tile,
                                        int cell = -1);

// Per-tile heat values for the camera view and the export.
enum class HeatMode { ListLength, FalsePositives, Efficiency, FalseNegatives, Overflow };
// "list-length", "false-positives", "efficiency", "false-negatives", "overflow"
const char* toString(HeatMode m);
// NaN where the tile holds no geometry. With W_t and E_t the shading and
// exact work of the tile's pixels (sums of GroundTruth::listShadingWork and
// listExactWork over the tile's lists):
// - ListLength: the longest list of the tile (the longest loop one of its pixels runs);
// - FalsePositives: W_t - E_t, light evaluations no pixel needed;
// - Efficiency: E_t / W_t (1 when W_t = 0);
// - FalseNegatives: the tile's false negatives, sum over its pixels of the
//   lights they need and their list lacks (0 for `all`);
// - Overflow: the entries the engine limits (CullSettings::cap, maxEntries)
//   dropped from the tile's lists, NaN for a tile none of whose lists was
//   over-full (so only over-full tiles are drawn: a filter).
// For `all` the ground truth keeps no per-tile work (its one list spans every
// tile), so FalsePositives and Efficiency are NaN there.
std::vector<double> tileHeat(const RunOutput& run, HeatMode mode);

// ---- the primitive a spot test used ------------------------------------------

// One chunk of a tile that the culling pass tested spot light `light` against
// (the tile's frustum, a halfz half, or a clustered froxel), with the sphere
// the cone-sphere test built around it and the chunk test's verdict.
struct SpotTestChunk {
    std::uint32_t list = 0; // the list (CullResult numbering) the verdict is for
    std::uint32_t cell = 0; // tileCells' order; 0 for a tile-wide chunk
    FrustumChunk chunk;
    BoundingSphere sphere;  // chunkBoundingSphere(chunk): what ConeSphere tests the cone against
    // spotIntersectsChunk(test, sphere test, cone, chunk): the light goes into
    // `list` exactly when this holds (and, for 2.5d, its cull sphere's depth
    // range meets an occupied cell; and the light's projected screen bounds
    // cover the tile, a conservative pre-filter).
    bool passed = false;
};
// What the run's spot test evaluated for spot light `light` (ViewLights
// numbering) and, when `tile` >= 0, for that tile: the light's cone (view
// space), the culling sphere every chunk test starts with (spotCullSphere:
// the apex sphere or the tight sphere), and the tile's chunks the pass tested
// it against, as the pass builds them:
// - naive, minmax, 2.5d: the tile's frustum (tileFrustum; 2.5d tests its
//   whole tile, its cells only gate by depth);
// - halfz: both halves (tileCells);
// - clustered: the froxels of the tile that the cull sphere's depth range
//   reaches (lightCellRange), only occupied ones under skip-empty;
// - all, and tiles the pass skips (no geometry): none.
// nullopt when `light` is not a spot light of the run.
struct SpotTestPrimitive {
    SpotTest test = SpotTest::ApexSphere;
    SpotCone cone;
    BoundingSphere cullSphere;
    std::vector<SpotTestChunk> chunks;
};
std::optional<SpotTestPrimitive> spotTestPrimitive(const RunOutput& run, const Projection& proj,
                                                   std::uint32_t light, int tile);

// ---- overlays.vtm -----------------------------------------------------------

struct OverlayExportOptions {
    // Depth cells are written for every cell while the run has at most this
    // many (tiles x cells); above it only occupied cells are written (a 1080p
    // clustered run has 261,120 froxels: megabytes of mostly empty boxes).
    std::size_t maxAllCells = 65536;
};

// Writes `dir`/overlays.vtm (a vtkMultiBlockDataSet in VTK XML) and its
// pieces in `dir`/overlays/: camera_frustum.vtp, tile_frustums.vtp,
// depth_cells.vtp and light_spheres.vtp, in world space. Array names are in
// docs/FORMATS.md. `dir` must exist; files are written and fsynced but not
// staged: exportDiagnostics makes the whole folder atomic. Throws Error when
// the run does not match the scene's camera (resolution, tile size) or a
// write fails.
void writeOverlaysVtm(const Scene& scene, const RunOutput& run, const std::string& dir,
                      const OverlayExportOptions& options = {});

} // namespace lc
