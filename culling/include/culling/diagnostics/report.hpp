#pragma once
// The speed-against-error report: one scene and camera, every configuration
// of the culling parameters that applies (algorithm x tile size x cells x
// slicing x sphere test x ...), on every backend asked for. Per configuration:
// culling and shading time (medians), efficiency, false negatives, list sizes,
// result bytes and the Lambert image error against the all-lights image.
// Shared by `lightcull report` and the studio's Report dock.
//
// The sweep is built from the parameter table (lc::cullParams()): a parameter
// added there is swept over all its choices (Choice, Bool) wherever
// paramAppliesTo() says it matters; Int parameters other than tile and cells
// keep their value.

#include "culling/custom/custom_cull.hpp"
#include "culling/diagnostics/export.hpp"
#include "culling/core/params.hpp"
#include "culling/scene/scene.hpp"

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace lc {

struct CancelToken;

// One configuration: a backend and one value per culling parameter.
struct ReportConfig {
    std::string backend;
    CullSettings settings;
    std::uint32_t tileSize = 16;
    // Every parameter of the table except width/height, by name: its value
    // as text, or empty when it does not apply to the algorithm.
    std::map<std::string, std::string> params;
    // A custom shader's row: "custom:my_cull.comp fixed:64 tile" (then label() is this).
    std::string customLabel;
    // An engine preset's row (ReportOptions::presets): its name; label() is
    // then "preset:NAME".
    std::string preset;
    // "2.5d tile=16 test=planes cells=32 slicing=log" (applicable ones only).
    std::string label() const;
};

struct ReportRow {
    ReportConfig config;
    std::string device;
    double cullMs = -1, shadeMs = -1, totalMs = -1; // medians over the repeats; total = cull + shade
    double efficiency = 1.0;
    // Against the best lists of the row's own grid (Metrics::optimalWork).
    std::uint64_t optimalWork = 0;
    double efficiencyVsOptimal = 1.0;
    std::uint64_t falseNegatives = 0;
    // Of those, the engine limits' (list full: a cap or record buffer; light
    // limit), and the lists they left over-full.
    std::uint64_t falseNegativesListFull = 0, falseNegativesLightLimit = 0, overflowLists = 0;
    // The longest list the culling test made before any cap: the smallest cap
    // that never overflows.
    std::uint32_t longestUncapped = 0;
    // A preset's row with misses from its limits: the first setting change
    // that removes them, found by culling again ("max-lights 300, cap 41"),
    // or why none of the limits is to blame. Empty otherwise.
    std::string fix;
    double meanList = 0;
    std::uint32_t maxList = 0;
    std::uint64_t resultBytes = 0;
    double imageRmse = 0, imageMaxError = 0;
    // On its backend's Pareto front (rows with false negatives never are):
    // no other row is at least as fast and at least as efficient (resp. has at
    // most the image error), and better in one of the two.
    bool paretoEfficiency = false, paretoError = false;
};

struct ReportOptions {
    std::vector<std::string> backends; // empty: every available backend
    std::string device;                // Vulkan device (see makeBackend)
    std::vector<std::uint32_t> tileSizes{8, 16, 32};
    std::vector<std::uint32_t> cellCounts{1, 2, 4, 8, 16, 32};
    // Parameters held at one value instead of swept (name -> value as text),
    // or swept over a subset of their values: a comma-separated list
    // ("minmax,halfz"; for tile and cells it replaces tileSizes/cellCounts).
    std::map<std::string, std::string> fixed;
    int repeat = 3; // timed runs of cull and of shade per configuration
    int warmup = 1; // untimed runs before them (first-use pipeline compiles)
    // Custom culling shaders (docs/CUSTOM_CULLING.md), one row each at the
    // scene camera's tile size (at each of fixed["tile"] where given, the
    // label then ending " tile=N"), beside the vulkan rows: on the vulkan
    // backend's depth when it ran, else the first backend's.
    std::vector<CustomShaderOptions> shaders;
    // Engine presets (core/presets.hpp) to run side by side instead of the
    // sweep: one row each per backend, at the preset's own grid and limits.
    std::vector<std::string> presets;
    // A cancel returns the rows finished so far (Report::cancelled set)
    // instead of throwing Cancelled: the studio shows what a long sweep made.
    bool partialOnCancel = false;
    // Where the swept backends come from. Null: each opened for the sweep
    // (makeBackend(name, device)). Else the caller's, kept open and shared
    // (the studio sweeps on its culling worker's device); it may throw
    // Error as makeBackend does.
    std::function<CullBackend&(const std::string& name)> backendFor;
};

struct Report {
    std::string sceneName;
    std::uint32_t width = 0, height = 0;
    std::size_t lights = 0;
    int repeat = 0, warmup = 0;
    std::vector<std::string> paramNames; // CSV parameter columns, table order
    // Per backend that ran: its device and timing method.
    std::vector<std::pair<std::string, std::string>> backendDevices, backendTiming;
    std::vector<std::string> notes;      // e.g. a backend that could not open
    std::vector<ReportRow> rows;
    // Configurations the sweep queued (backends that opened, custom shaders):
    // rows.size() unless the sweep was cancelled.
    std::size_t queued = 0;
    bool cancelled = false; // a partial report (ReportOptions::partialOnCancel)
};

// Whether parameter `name` changes what `algorithm` computes (with `cells`:
// slicing does not matter for one cell; parameters named spot-* matter only
// when the scene has a spot light). Other parameters apply to every algorithm
// but `all`.
bool paramAppliesTo(const std::string& name, Algorithm algorithm, std::uint32_t cells,
                    bool sceneHasSpotLights = false);
// The same for full settings: the engine limits (cap, max-lights,
// max-entries) apply to every algorithm, `all` included; overflow only with a
// cap or record buffer set, limit-keep only with a light limit.
bool paramAppliesTo(const std::string& name, const CullSettings& settings, bool sceneHasSpotLights = false);

// The configurations of one backend, in sweep order. Throws SettingsError for
// an unknown or invalid fixed parameter.
std::vector<ReportConfig> reportConfigs(const ReportOptions& options, const std::string& backend,
                                        bool sceneHasSpotLights = false);

// progress(done, total, label of the configuration just finished).
using ReportProgress = std::function<void(std::size_t, std::size_t, const std::string&)>;

// Runs the sweep. Per backend: one depth pre-pass and one all-lights shading,
// then per configuration `repeat` culls and shades and the ground truth.
// Throws Cancelled when `cancel` fires (unless options.partialOnCancel), Error
// for bad input; a backend that cannot be opened is skipped with a note unless
// it is the only one asked for.
Report runReport(const Scene& scene, const ReportOptions& options, const ReportProgress& progress = {},
                 const CancelToken* cancel = nullptr);

// Sets the Pareto flags of `rows` (per backend).
void markPareto(std::vector<ReportRow>& rows);

std::string reportCsv(const Report& report);      // docs/FORMATS.md, "report.csv"
std::string reportMarkdown(const Report& report); // table and a reading of it
RgbImage paretoImage(const Report& report);       // time vs efficiency | time vs image error

// An axis of pareto.png: ticks at round values (1, 2 or 5 times a power of
// ten, about `target` of them) and the range they span, which holds [lo, hi].
// On a log axis (lo > 0) the ticks are 1, 2 and 5 per decade, or 1 alone
// when the axis spans more than three decades.
struct AxisTicks {
    double lo = 0, hi = 1;
    std::vector<double> ticks;
};
AxisTicks axisTicks(double lo, double hi, bool log, int target = 4);
// A tick's label: the value itself, as few digits as it needs ("1500", "0.25", "2e+06").
std::string tickText(double v);
// The colour of an algorithm's points (RGB in [0, 1]), one per algorithm, in
// pareto.png and the studio's Report chart alike.
glm::dvec3 algorithmColour(Algorithm a);

// Writes report.csv, report.md and pareto.png into `dir` atomically (staged
// in a sibling folder, renamed at the end; an existing `dir` is replaced only
// when it holds nothing but report outputs). Throws Error naming the path.
void writeReport(const Report& report, const std::string& dir);
// writeReport's checks of `dir` alone (throws Error), before the sweep.
void checkReportFolder(const std::string& dir);

} // namespace lc
