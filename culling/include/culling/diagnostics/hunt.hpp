#pragma once
// The hunt (issue 35, `lightcull hunt`): many small random trials of one
// culling (a built-in algorithm with its settings, or a custom shader), each
// judged by exact ground truth, stopping at the first trial whose property
// fails; that trial is then shrunk (fewer lights, a smaller screen, rounder
// camera values) while it still fails. Deterministic for a seed: a trial's
// scene is a pure function of (base scene, seed, trial index, dimensions).
//
// The property is the one `lightcull run` judges with its exit code 3: no
// false negatives, and for custom shaders no index past the light count, no
// light twice in one list, no validation message and (with
// overflowIsFailure) no list over the layout's declared capacity; for a
// built-in algorithm on a backend other than the CPU reference, also every
// entry the CPU reference lists over the same depth image.

#include "culling/core/backend.hpp"
#include "culling/core/params.hpp"
#include "culling/core/presets.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/custom/custom_cull.hpp"
#include "culling/scene/camera_path.hpp"
#include "culling/scene/scene.hpp"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

namespace lc {

// What a trial varies (`--vary`); every one is on by default.
enum HuntDim : unsigned {
    HuntCamera = 1u << 0,     // position and direction around and inside the scene's bounds
    HuntProjection = 1u << 1, // kind (perspective, GL, reversed-Z, orthographic), fov, near, far
    HuntScreen = 1u << 2,     // width, height (multiples of the tile and not), tile size
    HuntLights = 1u << 3,     // count, positions, radii
    HuntSpots = 1u << 4,      // some lights are spots, outer half-angle up to 90 degrees (a 180-degree cone)
    HuntSceneDim = 1u << 5,   // generated scenes (only when no scene is given)
    HuntAll = (1u << 6) - 1,
};
// "camera,projection,screen,lights,spots,scene" (any subset, or "all").
// Throws SettingsError("vary", ...) for an unknown name.
unsigned parseHuntDims(const std::string& text);
std::string huntDimsToString(unsigned dims);

// How many trials exercised each corner the issue names (the progress line).
struct HuntCoverage {
    std::uint64_t trials = 0, orthographic = 0, reversedZ = 0, glDepth = 0, infiniteFar = 0;
    std::uint64_t nonMultipleScreens = 0, tinyScreens = 0, cameraInsideBounds = 0, generatedScenes = 0;
    std::uint64_t spotTrials = 0, wideSpots = 0; // wideSpots: a spot cone wider than 90 degrees
    std::uint64_t crowds = 0;                     // trials of 33..300 lights around one point
    std::uint64_t lightsBehindCamera = 0, lightsCrossingNear = 0, lightsLargerThanScene = 0;
    std::uint64_t emptyViews = 0;   // trials whose camera saw no geometry (nothing to judge)
    std::uint64_t overCapacity = 0; // trials whose lists overflowed a declared capacity (not failures by default)
    std::string text() const;       // "30 orthographic, 24 reversed-Z, ..."
};

struct HuntOptions {
    // The culling under test: `shader` when set, else the built-in `settings`
    // on the backend passed to hunt().
    CullSettings settings;
    // An engine preset instead of `settings` (docs/ENGINES.md): every trial is
    // culled with the preset's settings derived for that trial's screen and
    // light count, as the engine derives them (its tile size too), with
    // `presetOverrides` (parameter, value) over them as lc::applyPreset sets them.
    const EnginePreset* preset = nullptr;
    std::vector<std::pair<std::string, std::string>> presetOverrides;
    std::optional<CustomShaderOptions> shader;
    std::uint64_t seed = 1;
    std::uint64_t maxTrials = 200; // 0: no count limit (then maxSeconds must be > 0)
    double maxSeconds = 0;         // 0: no time limit
    unsigned vary = HuntAll;
    // A list over a custom layout's declared capacity (fixed:N, compact:N) is
    // a limit the user chose: by default such a trial is counted apart
    // (HuntCoverage::overCapacity) unless its culling test also missed a
    // light; true makes overflow itself a failure.
    bool overflowIsFailure = false;
    // The scene whose meshes every trial uses (and whose camera, lights and
    // screen stand for the dimensions not varied). Null: a generated scene
    // (ground plane and boxes at several depths), a new one per trial when
    // `scene` is varied.
    const Scene* baseScene = nullptr;
    // Called about once a second and at the end.
    std::function<void(const HuntCoverage&, double seconds)> progress;
    // Checked between trials and between the shrinking's runs: a cancelled
    // hunt returns what it covered (HuntResult::cancelled), and a failure
    // found before, shrunk as far as it got.
    const CancelToken* cancel = nullptr;
};

// One judged trial.
struct HuntVerdict {
    bool fails = false;
    bool overCapacity = false; // lists overflowed a declared capacity (custom)
    std::string property;      // what failed: "false negatives", "invalid indices", "validation messages: ...",
                               // "duplicate indices", "overflow", "lists lack the CPU reference's entries", "error: ..."
    std::uint64_t falseNegatives = 0, invalidIndices = 0, overflowLists = 0;
    std::uint64_t duplicateIndices = 0, validationMessages = 0; // custom shaders
    // Built-in algorithm on Vulkan: entries of the CPU reference's lists (over
    // the same depth image) its lists lack; the first such list and light.
    std::uint64_t missingReferenceEntries = 0;
    std::uint32_t referenceList = 0, referenceLight = 0;
    std::uint64_t geometryPixels = 0;
    std::optional<MissedLight> miss; // the first located miss (culling test first)
};

struct HuntFailure {
    std::uint64_t trial = 0;     // 0-based index of the failing trial
    Scene original, shrunk;      // the failing trial as generated, and shrunk
    HuntVerdict verdict;         // of `shrunk`
    std::string varied;          // what the trial varied, in words
    std::size_t shrinkRuns = 0;  // pipeline runs the shrinking took
    // Set for a camera path's frame: where it failed, in words ("frame 12
    // (t = 0.4 s) of ..."), said instead of the trial and seed.
    std::string pathFrame;
};

struct HuntResult {
    HuntCoverage coverage;
    double seconds = 0;
    std::optional<HuntFailure> failure;
    std::optional<std::uint64_t> firstOverCapacityTrial;
    bool cancelled = false;
    std::string path; // a camera path's description when the trials were its frames (huntResultOf)
};

// The scene of trial `index` (pure: the same arguments give the same scene).
Scene makeHuntTrial(const Scene* base, std::uint64_t seed, std::uint64_t index, unsigned vary);
// A generated scene: a ground plane, 1..6 boxes at several depths (some
// floating), 0..2 spheres and 0..3 sliver triangles (a thousandth as wide as
// long), with a framing camera at 160x96 and 8 lights (deterministic in
// `seed`).
Scene makeHuntScene(std::uint64_t seed);

// The settings a built-in hunt culls `scene` with: options.settings, or with
// a preset its settings for this scene (then the camera's tile size is the
// preset's too).
CullSettings huntSettings(const HuntOptions& options, Scene& scene);

// Runs the culling on `scene` (depth pre-pass on `backend`, ground truth,
// no image error) and judges the property. `run` receives the output when
// non-null. Pipeline errors (a custom shader's hang, a device error) are
// failures ("error: ..."); an invalid scene throws.
HuntVerdict judgeHuntTrial(const Scene& scene, const HuntOptions& options, CullBackend& backend,
                           RunOutput* run = nullptr);

// Searches; stops at the first failing trial (shrunk) or the budget.
HuntResult hunt(const HuntOptions& options, CullBackend& backend);

// Shrinks a failing scene while it still fails: every light but the missed
// one dropped where it can be, the screen halved, camera values rounded.
// `runs` counts the pipeline runs.
Scene shrinkHuntFailure(const Scene& failing, const HuntOptions& options, CullBackend& backend,
                        std::size_t* runs = nullptr);

// The one-paragraph verdict of a failure (verdict.txt).
std::string huntVerdictText(const HuntFailure& f, const HuntOptions& options);

// The repro folder (`lightcull hunt --out`, the studio's Culling > Hunt):
// what it may already hold, and writing it.
//
// Empty when `dir` can take a repro: it does not exist yet (its parent does)
// or holds nothing but an earlier hunt's output; else why not, naming `dir`.
std::string huntOutputProblem(const std::string& dir);

// Writes the repro into `dir` (created; an earlier hunt's output there is
// replaced): scene.json (the shrunk scene), scene.glb (the same as glTF, with
// the camera and KHR_lights_punctual lights; extras.lightcull keeps what glTF
// cannot say), repro.sh (the `lightcull run`
// that shows the miss; exits 3 while it is there), run/ (that run's
// diagnostics), summary.json (run/'s) and verdict.txt. Without a failure,
// only verdict.txt ("no miss in N trials ..."). `device` and `validation`
// (custom shaders) go into the command as given to the hunt. Returns the
// command (starting "lightcull run"), empty without a failure.
std::string writeHuntRepro(const HuntResult& result, const HuntOptions& options, CullBackend& backend,
                           const std::string& dir, const std::string& device = {});

// "no miss in N trials of seed S (coverage: ...)".
std::string huntNoMissText(const HuntResult& result, const HuntOptions& options);

// --- camera paths (`lightcull hunt --path`) ----------------------------------
// Bugs users report as flicker show along a camera path: every frame of the
// path is judged (the scene's meshes, lights and screen; the frame's camera)
// instead of random trials; the worst frame is shrunk into the repro.

struct HuntPathFrameResult {
    double time = 0;
    HuntVerdict verdict;
};

struct HuntPathResult {
    std::vector<HuntPathFrameResult> frames; // one per path frame, in order (fewer when cancelled)
    std::size_t failingFrames = 0;
    // The frame with the most false negatives among the failing ones (the
    // first such frame on a tie); its shrunk repro in `failure` (its `trial`
    // is the frame index). Empty when no frame fails.
    std::optional<std::size_t> worst;
    std::optional<HuntFailure> failure;
    double seconds = 0;
    bool cancelled = false;
    std::string description; // the path's
};

// Judges `scene` through every camera of `path` with the culling under test
// (options.settings or options.shader; options.cancel is honoured between
// frames; options.progress gets the frames done as trials). Seeds, budgets
// and dimensions of `options` are not used.
HuntPathResult huntPath(const HuntOptions& options, const Scene& scene, const CameraPath& path, CullBackend& backend);

// A path result as the random hunt's (coverage.trials = frames judged), for
// writeHuntRepro and huntVerdictText.
HuntResult huntResultOf(const HuntPathResult& r);

// path.csv (frame, time, false negatives, ..., property) and path.svg (the
// false negatives per frame, failing frames marked, the worst one named) into
// `dir`, which writeHuntRepro prepared.
void writeHuntPathReport(const HuntPathResult& r, const CameraPath& path, const std::string& dir);

} // namespace lc
