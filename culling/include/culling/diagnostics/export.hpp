#pragma once
// Diagnostics export, shared by the CLI (`run --out`) and the studio.

#include "culling/core/pipeline.hpp"
#include "culling/truth/shade.hpp"

#include <string>

namespace lc {

// summary.json text (see docs/FORMATS.md for every key).
std::string summaryJson(const Scene& scene, const CullSettings& settings, const RunOutput& run);
// tiles.csv text: tile_x,tile_y,cell,view_depth_min,view_depth_max,cell_mask,count,lights
std::string tilesCsv(const RunOutput& run);
// heatmap.png: the depth image tinted per tile by list length, with a legend.
// Returns RGB8 pixels (width x height, plus the legend band) and its size.
struct RgbImage {
    std::uint32_t width = 0, height = 0;
    std::vector<std::uint8_t> rgb;
};
RgbImage heatmapImage(const RunOutput& run);
// heatmap_misses.png: the depth image in grey with every tile that misses
// lights in red, brighter with more false negatives (tileHeat's
// FalseNegatives, log scale), and a legend line with the counts.
RgbImage missHeatmapImage(const RunOutput& run);
void writePng(const RgbImage& img, const std::string& path);

// shaded_culled.png, shaded_all.png (one exposure: the all-lights image's
// 99th percentile at 0.9, sRGB) and shaded_diff.png (|culled - all| scaled so
// the largest error is white) of run.shadedCulled / run.shadedAll, into `dir`.
// exportDiagnostics writes them too when the run kept its shaded images
// (RunOptions::keepShadedImages).
void writeShadedImages(const RunOutput& run, const std::string& dir);

// The three pictures writeShadedImages writes (RGB8, row 0 at the top), for a
// caller that shows them (the studio's camera view shows exactly these
// pixels), with the exposure of the two shaded ones and the image error that
// scales the difference (error.maxAbs is white). Throws Error as
// writeShadedImages does.
struct ShadedPictures {
    RgbImage culled, all, difference;
    double exposure = 1;
    ImageError error;
};
ShadedPictures shadedPictures(const RunOutput& run);

// An extra image a caller adds to the export (the studio's view screenshots):
// `fileName` must be one of kExportViewImages.
struct NamedImage {
    std::string fileName;
    RgbImage image;
};
inline constexpr const char* kExportViewImages[] = {"camera_view.png", "inspector_view.png"};

// Writes summary.json, tiles.csv, heatmap.png, overlays.vtm with its pieces in
// overlays/ (culling/diagnostics/overlays.hpp) and any `viewImages` into `dir` atomically:
// all files go to a temporary sibling folder that is renamed onto `dir` at the
// end; on any failure nothing is left behind and an existing `dir` is
// untouched until the rename. Throws Error naming the path.
void exportDiagnostics(const Scene& scene, const CullSettings& settings, const RunOutput& run,
                       const std::string& dir, const std::vector<NamedImage>& viewImages = {});
// Whether exportDiagnostics could write into `dir` (its parent exists; it is
// absent, empty or an earlier export): throws Error saying why not. For
// callers to check before the run.
void checkDiagnosticsFolder(const std::string& dir);

} // namespace lc
