// lightcull: the command-line front end of the culling library.
//
//   lightcull scenes
//   lightcull run (--scene FILE | --builtin NAME) [culling flags] [--lights N [--seed S]]
//                 [--backend cpu|vulkan] [--device D] [--no-image-error] --out DIR
//   lightcull bench (--scene FILE | --builtin NAME) [run flags] [--repeat N] [--warmup N]
//                   [--sweep KEY=V1,V2,...]... [--json FILE]
//   lightcull hunt [--scene FILE | --builtin NAME] [culling flags | --shader FILE] [--seed S]
//                  [--trials N] [--budget SECONDS] [--vary DIMS] [--overflow] --out DIR
//   lightcull convert IN OUT        (IN: scene JSON, .gltf, .glb; OUT by extension: .json, .gltf, .glb)
//
// FILE is scene JSON, .gltf or .glb (with --camera and --min-intensity for glTF).
//
// The culling flags are generated from lc::cullParams(), the one parameter
// table (see docs/CLI.md). Errors print one line on stderr and exit non-zero:
// 2 for a bad command line, 1 for anything that failed while running.

#include "culling/capture/capture_frame.hpp"
#include "culling/capture/renderdoc_capture.hpp"
#include "culling/core/errors.hpp"
#include "culling/diagnostics/explain.hpp"
#include "culling/diagnostics/export.hpp"
#include "culling/diagnostics/report.hpp"
#include "culling/core/file_io.hpp"
#include "culling/core/params.hpp"
#include "culling/math/light_proxy.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/core/presets.hpp"
#include "culling/core/text.hpp"
#include "culling/scene/scene_io.hpp"
#include "custom.hpp"
#include "hunt.hpp"
#include "report.hpp"
#include "scene_source.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <functional>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <regex>
#include <string>

#ifndef LC_VERSION
#define LC_VERSION "unknown"
#endif

namespace {

std::string oneLine(std::string s) {
    for (char& c : s)
        if (c == '\n' || c == '\r') c = ' ';
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s;
}

// What `check` (a file_io check of an output path) says is wrong, or empty:
// a bad output path is a bad command line (exit 2), found before the work.
std::string outputProblem(const std::function<void()>& check) {
    try {
        check();
    } catch (const lc::Error& e) {
        return e.what();
    }
    return {};
}

// CLI11's wording of a bad command line, said as the rest of the CLI says
// it: the flag first, then what it takes and what it got. Messages it does
// not recognise pass through unchanged. `command`: the subcommand, for the
// --help it points at.
std::string plainParseError(const std::string& what, const std::string& command) {
    static const std::regex range(R"(^(\S+): Value (.*) not in range (\S+) to (\S+)$)");
    static const std::regex convert(R"(^Could not convert: (\S+) = (.*)$)");
    static const std::regex unexpected(R"(^The following arguments? (?:was|were) not expected: (.*)$)");
    const std::string help = "lightcull" + (command.empty() ? std::string() : " " + command) + " --help";
    // CLI11 prints a floating-point range's ends as 1.000000.
    const auto number = [](const std::string& n) {
        static const std::regex whole(R"(^(-?\d+)\.0+$)");
        return std::regex_replace(n, whole, "$1");
    };
    std::smatch m;
    if (std::regex_match(what, m, range))
        return m[1].str() + ": expected a number from " + number(m[3].str()) + " to " + number(m[4].str()) +
               ", got '" + m[2].str() + "'";
    if (std::regex_match(what, m, convert)) return m[1].str() + ": '" + m[2].str() + "' is not a number";
    if (std::regex_match(what, m, unexpected))
        return "'" + m[1].str() + "' is not an option or argument here (see " + help + ")";
    return what;
}

int fail(int code, const std::string& message) {
    std::cerr << "lightcull: error: " << oneLine(message) << "\n";
    return code;
}

std::string paramDescription(const lc::ParamSpec& p) {
    std::string d = p.help;
    if (p.type == lc::ParamType::Choice) {
        d += " {";
        for (std::size_t i = 0; i < p.choices.size(); ++i) d += (i ? "|" : "") + p.choices[i];
        d += "}";
    } else if (p.type == lc::ParamType::Int) {
        d += " [" + std::to_string(p.minValue) + ".." + std::to_string(p.maxValue) + "]";
    } else if (p.type == lc::ParamType::Real) {
        d += " [" + lc::realText(p.realMin) + ".." + lc::realText(p.realMax) +
             (p.realWord.empty() ? "" : " or " + p.realWord) + "]";
    } else {
        d += " {true|false}";
    }
    return d + " (default: " + p.defaultValue + ")";
}

std::string fmt(const char* f, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, v);
    return buf;
}

std::string ms(double v) { return v < 0 ? std::string("n/a") : fmt("%.2f ms", v); }

// The command line as a shell would take it back (summary.json records it).
std::string commandLine(int argc, char** argv) {
    std::string out;
    for (int i = 0; i < argc; ++i)
        out += (i ? " " : "") + lc::shellQuote(i == 0 ? std::string("lightcull") : std::string(argv[i]));
    return out;
}

// docs/CLI.md, "Errors and exit codes": exit 3 when the judged culling misses
// lights, overflows a list, writes an index past the light count or a light
// twice in one list (shaded twice), or set off the validation layer, so that
// a CI job fails on a miss without reading summary.json.
constexpr int kExitMisses = 3;
int verdictExit(const lc::RunOutput& run) {
    const std::uint64_t fn = run.truthComputed ? run.truth.metrics.falseNegatives : 0;
    const std::uint64_t overflow = run.custom ? run.custom->overflowLists : 0;
    const std::uint64_t invalid = run.custom ? run.custom->invalidIndices : 0;
    const std::uint64_t duplicate = run.custom ? run.custom->duplicateIndices : 0;
    const std::size_t validation = run.custom ? run.custom->validationMessages.size() : 0;
    if (fn == 0 && overflow == 0 && invalid == 0 && duplicate == 0 && validation == 0) return 0;
    if (!run.custom) {
        // A built-in algorithm: its misses by cause (the engine limits' drops are losses too).
        const lc::Metrics& m = run.truth.metrics;
        std::cerr << "lightcull: the culling fails: " << fn << (fn == 1 ? " false negative" : " false negatives")
                  << " (culling test "
                  << m.falseNegativesCullingTest() << ", list full " << m.falseNegativesListFull << ", light limit "
                  << m.falseNegativesLightLimit << "), " << run.result.limits.overflowLists.size()
                  << " over-full lists (exit " << kExitMisses << ")\n";
        return kExitMisses;
    }
    std::cerr << "lightcull: the culling fails: " << lc::countOf(fn, "false negative", "false negatives") << ", "
              << lc::countOf(overflow, "overflowed list", "overflowed lists") << ", "
              << lc::countOf(invalid, "invalid index", "invalid indices");
    if (duplicate) std::cerr << ", " << lc::countOf(duplicate, "duplicate index", "duplicate indices");
    if (validation) std::cerr << ", " << lc::countOf(validation, "validation message", "validation messages");
    std::cerr << " (exit " << kExitMisses << ")\n";
    return kExitMisses;
}

void printCaptureActions(const lc::CaptureInfo& info) {
    std::size_t dispatches = 0;
    for (const lc::CaptureAction& a : info.actions) {
        dispatches += a.kind == "dispatch";
        std::cout << a.event << "  " << a.kind << "  " << a.name;
        if (a.kind == "dispatch") std::cout << " " << a.dims[0] << "x" << a.dims[1] << "x" << a.dims[2];
        if (!a.markers.empty()) std::cout << "  [" << a.markerPath() << "]";
        std::cout << "\n";
    }
    std::cout << info.actions.size() << " actions, " << dispatches << " dispatches (RenderDoc " << info.renderdoc
              << "); lightcull capture-info " << lc::shellQuote(info.file)
              << " --dispatch EVENT lists a dispatch's bindings\n";
}

void printCaptureBindings(const lc::CaptureInfo& info) {
    std::cout << "event " << info.event << ": " << info.bindings.size() << " bindings\n";
    for (const lc::CaptureBinding& b : info.bindings) {
        std::cout << "  " << b.set << "." << b.binding << (b.element ? "[" + std::to_string(b.element) + "]" : "")
                  << "  " << b.kind << " " << b.descriptor;
        if (b.kind == "buffer")
            std::cout << "  " << b.size << " bytes at offset " << b.offset << " of " << b.length;
        else if (b.kind == "image")
            std::cout << "  " << b.width << "x" << b.height << " " << b.format
                      << (b.samples > 1 ? " x" + std::to_string(b.samples) + " samples" : "");
        std::cout << "  " << b.resource << (b.variable.empty() ? "" : "  (shader: " + b.variable + ")") << "\n";
    }
}

void printSummary(const lc::Scene& scene, const lc::CullSettings& settings, const lc::RunOutput& run,
                  const std::string& out, const std::string& noImageErrorWhy = "--no-image-error") {
    const lc::CullResult& r = run.result;
    const lc::Metrics& m = run.truth.metrics;
    // Nothing to judge reads like a perfect culler: say so.
    if (run.truthComputed && m.geometryPixels == 0)
        std::cerr << "lightcull: warning: the camera sees no geometry (0 geometry pixels): there is nothing to "
                     "cull for, and every metric is trivially perfect; check the camera\n";
    std::cout << "scene " << scene.name << ": " << r.grid.width << "x" << r.grid.height << ", tile "
              << r.grid.tileSize << " (" << r.grid.tilesX << "x" << r.grid.tilesY << " tiles), "
              << run.lights.size() << (run.lights.size() == 1 ? " light\n" : " lights\n")
              << "algorithm "
              << (run.custom ? std::string("custom")
                             : settings.algorithm == lc::Algorithm::Raster
                                   // raster draws proxies: no sphere test; cells only with slices
                                   ? std::string("raster") +
                                         (settings.proxySlices ? ", cells " + std::to_string(settings.cells) +
                                                                     ", slicing " + lc::toString(settings.slicing)
                                                               : std::string())
                             : std::string(lc::toString(settings.algorithm)) + ", test " + lc::toString(settings.test) +
                                   // Only the settings this algorithm reads.
                                   (settings.algorithm == lc::Algorithm::ZBin ? ", bins " + std::to_string(settings.bins)
                                    : settings.algorithm == lc::Algorithm::TwoPointFiveD ||
                                            settings.algorithm == lc::Algorithm::Clustered
                                        ? ", cells " + std::to_string(settings.cells) +
                                              (settings.cells > 1 ? ", slicing " + std::string(lc::toString(settings.slicing))
                                                                  : std::string())
                                        : std::string()))
              << ", backend " << r.backend << " (" << r.device << ")\n"
;
    // With misses, efficiency is no score: it counts only what the lists hold,
    // and lists that drop needed lights can look tighter than the optimum.
    if (m.falseNegatives > 0)
        std::cout << "FALSE NEGATIVES " << m.falseNegatives
                  << ": the culling misses lights that pixels need (efficiency below is not a score)\n"
                  << "efficiency " << fmt("%.4f", m.efficiency) << ", " << fmt("%.1f", 100.0 * m.efficiencyVsOptimal)
                  << "% of this grid's optimum: meaningless with false negatives (exact work " << m.exactWork
                  << " / shading work " << m.shadingWork << ")\n";
    else
        std::cout << "false negatives 0, efficiency " << fmt("%.4f", m.efficiency) << " (exact work " << m.exactWork
                  << " / shading work " << m.shadingWork << ")\n"
                  << "optimum of this grid: " << fmt("%.1f", 100.0 * m.efficiencyVsOptimal) << "% (optimal work "
                  << m.optimalWork << " / shading work " << m.shadingWork << ")\n";
    if (m.falseNegatives > 0 && !run.custom) {
        // The first miss, culling test first, most pixels first: where to look.
        const auto located = lc::locateFalseNegatives(run, lc::Projection(scene.camera));
        if (!located.empty()) {
            const lc::MissedLight& f = located.front();
            const std::uint32_t tx = f.tile % r.grid.tilesX, ty = f.tile / r.grid.tilesX;
            std::cout << "first miss: light " << f.light
                      << (f.light < scene.lights.size() ? " '" + scene.lights[f.light].name + "'" : std::string())
                      << " in tile " << tx << "," << ty << " (list " << f.list << "), " << f.pixels
                      << (f.pixels == 1 ? " pixel needs it" : " pixels need it") << " (of " << located.size()
                      << " missed light-list pairs" << (out.empty() ? "" : "; all in summary.json's \"missed\"")
                      << "); why: lightcull explain with the same flags and --tile " << tx << "," << ty
                      << (r.cellOfList(f.list) >= 0 ? " --cell " + std::to_string(r.cellOfList(f.list)) : std::string())
                      << " --light " << f.light << "\n";
        }
    }
    if (!run.custom && settings.hasLimits()) {
        // The engine limits: what they were and what they took.
        const lc::ListLimits& lim = r.limits;
        std::cout << "limits: cap " << settings.cap << ", max-lights " << settings.maxLights << " ("
                  << lc::toString(settings.limitKeep) << "), max-entries " << settings.maxEntries
                  << ", overflow-policy " << lc::toString(settings.overflow) << ": " << lim.overflowLists.size()
                  << " over-full lists, " << lim.droppedLights.size() << " entries dropped, " << lim.lightsOverLimit
                  << " lights past the limit; the longest list before the cap " << lim.longestUncapped << "\n";
        if (m.falseNegatives)
            std::cout << "misses by cause: culling test " << m.falseNegativesCullingTest() << ", list full "
                      << m.falseNegativesListFull << ", light limit " << m.falseNegativesLightLimit << "\n";
    }
    if (settings.algorithm == lc::Algorithm::Raster && !r.coverage.empty()) {
        const bool autoOverfit = settings.proxyOverfit <= 0;
        // How many lights each proxy shape stands for (those the light
        // limit keeps: the others are never drawn).
        std::size_t cones = 0, wide = 0, drawn = 0;
        for (std::uint32_t l = 0; l < run.lights.size(); ++l) {
            if (r.limits.isOverLimit(l)) continue;
            ++drawn;
            if (run.lights.isSpot(l))
                (run.lights.spotAngles[l] <= settings.proxyConeAngle * M_PI / 180.0 ? cones : wide)++;
        }
        const std::size_t spheres = drawn - cones;
        std::cout << "proxies: " << spheres << (spheres == 1 ? " icosphere" : " icospheres") << " of level " << settings.proxyLevel << " ("
                  << lc::unitIcosphere(settings.proxyLevel).triangles.size() << " triangles), overfit "
                  << fmt("%.4f", autoOverfit ? lc::icosphereEnclosingOverfit(settings.proxyLevel) : settings.proxyOverfit)
                  << (wide ? " (" + std::to_string(wide) + " of them spots wider than " +
                                 std::to_string(settings.proxyConeAngle) + " degrees)"
                           : std::string());
        if (cones)
            std::cout << "; " << lc::countOf(cones, "spot cone", "spot cones") << " of " << settings.proxySegments << " sides, overfit "
                      << fmt("%.4f", autoOverfit ? lc::coneEnclosingOverfit(settings.proxySegments) : settings.proxyOverfit);
        std::cout << (autoOverfit ? " (auto: each encloses its light)" : " (as set)") << "\n"
                  << "depth: "
                  << (settings.proxySlices ? "clusters: " + std::to_string(settings.cells) + " " +
                                                 lc::toString(settings.slicing) + " slices, the triangles' depths over "
                                                 "each tile, " +
                                                 (settings.skipEmpty ? "empty clusters skipped" : "empty clusters kept")
                                           : std::string("the proxy's depth range against each tile's min/max"))
                  << "\n"
                  << "coverage: " << r.coverage << "\n";
    }
    std::cout << "lists " << r.listCountTotal() << ", entries " << r.entries() << ", mean list "
              << fmt("%.2f", m.meanList) << ", max list " << m.maxList << ", " << m.resultBytes
              << " bytes\n";
    if (m.imageErrorComputed)
        std::cout << "image error: rmse " << fmt("%.6g", m.imageRmse) << ", max " << fmt("%.6g", m.imageMaxError) << "\n";
    else
        std::cout << "image error: not computed (" << noImageErrorWhy << ")\n";
    std::cout << "times (" << r.timingMethod << "): depth "
              << (run.depthReused ? "not run (" + (run.depthFrom.empty() ? std::string("depth image given") : run.depthFrom) + ")"
                                  : ms(r.timings.depthMs));
    if (r.depthTriangles) {
        std::cout << " (" << (run.depthFrom.empty() ? "" : run.depthFrom + ", ") << r.depthTrianglesDrawn << " of "
                  << r.depthTriangles << " triangles)";
    }
    std::cout << ", cull " << ms(r.timings.cullMs)
              << ", shade " << ms(r.timings.shadeMs) << ", ground truth " << ms(r.timings.groundTruthMs) << "\n"
              << "wrote " << out << "/summary.json, tiles.csv, heatmap.png, heatmap_misses.png"
              << (run.shadedAll.empty() ? "" : ", shaded_culled.png, shaded_all.png, shaded_diff.png")
              << (std::filesystem::exists(std::filesystem::path(out) / "overlays.vtm") ? ", overlays.vtm, overlays/" : "")
              << "\n";
}


// --preset's help: every engine preset by name.
std::string presetHelp() {
    std::string names;
    for (const lc::EnginePreset& p : lc::enginePresets()) names += (names.empty() ? "" : ", ") + p.name;
    return "Cull as a shipped engine does (docs/ENGINES.md): its algorithm, grid and limits; flags given beside it "
           "override it. NAME: " + names;
}

// Flags shared by `run` and `bench`: the scene, the culling parameters (from
// the one table), generated lights and the backend.
struct SceneFlags {
    lcli::SceneSource source;
    std::string backendName, device;
    long long lightCount = -1;
    unsigned long long seed = 1;
    double spotFraction = 0.0;
    std::map<std::string, std::string> paramValues;
    std::vector<std::pair<std::string, CLI::Option*>> paramOptions;
    CLI::Option* optLights = nullptr;
    std::string presetName;
    CLI::Option* optPreset = nullptr;

    // `tileSizeFlag`: the tile-size parameter's flag (explain's --tile names a tile).
    void addTo(CLI::App* cmd, const std::string& tileSizeFlag = "tile") {
        source.addTo(cmd);
        // One flag per culling parameter, straight from the parameter table.
        for (const lc::ParamSpec& p : lc::cullParams()) {
            CLI::Option* o = cmd->add_option("--" + (p.name == "tile" ? tileSizeFlag : p.name), paramValues[p.name],
                                             paramDescription(p));
            o->type_name(p.type == lc::ParamType::Int    ? "INT"
                         : p.type == lc::ParamType::Bool ? "BOOL"
                         : p.type == lc::ParamType::Real ? "REAL"
                                                         : "CHOICE");
            paramOptions.emplace_back(p.name, o);
        }
        optPreset = cmd->add_option("--preset", presetName, presetHelp())->type_name("NAME");
        optLights = cmd->add_option(
            "--lights", lightCount,
            "Replace the scene's lights with N generated ones (deterministic, placed in the scene's bounds)");
        optLights->type_name("N");
        cmd->add_option("--seed", seed, "Seed of the light generator used by --lights (default: 1)")
            ->type_name("S")
            ->needs(optLights);
        cmd->add_option("--spot-fraction", spotFraction,
                        "Fraction of the --lights that are spot lights (0..1, default 0; outer angles 15..45 "
                        "degrees, random directions)")
            ->type_name("F")
            ->needs(optLights);
        // Named without opening a device: help text built by every command
        // must not create a Vulkan instance (RenderDoc must load before one).
        cmd->add_option("--backend", backendName,
                        "Backend running depth and culling: cpu or vulkan (default: vulkan where a device opens, "
                        "else cpu)")
            ->type_name("NAME");
        cmd->add_option("--device", device,
                        "Vulkan device: index or name substring (default: LIGHTCULL_DEVICE, else the first discrete GPU)")
            ->type_name("D");
    }

    bool hasScene() const { return source.given(); }

    lc::Scene loadScene() const {
        lc::Scene scene = source.load();
        if (optLights->count()) replaceLights(scene, lightCount);
        return scene;
    }

    void replaceLights(lc::Scene& scene, long long count) const {
        if (count < 0 || count > 1000000)
            throw lc::SettingsError("lights", "must be in 0..1000000, got " + std::to_string(count));
        lc::LightGenSettings gen = lc::defaultLightGen(scene, std::uint32_t(count), seed);
        gen.spotFraction = spotFraction; // generateLights refuses values outside [0, 1]
        scene.lights = lc::generateLights(gen);
    }

    // The first culling parameter given on the command line that is not the
    // camera's (tile, width, height): with lists from a shader or a dump it
    // would have no effect. Empty when none.
    std::string givenCullingFlag() const {
        if (optPreset && optPreset->count()) return "--preset";
        for (const auto& [name, opt] : paramOptions)
            if (opt->count() && name != "tile" && name != "width" && name != "height") return opt->get_name();
        return {};
    }

    // The culling flags onto `settings` and the scene's camera: the camera's
    // size first, then --preset (its derived settings see that size and the
    // scene's lights), then every other flag, which overrides the preset.
    void applyParams(lc::CullSettings& settings, lc::Scene& scene) const {
        for (const auto& [name, opt] : paramOptions)
            if (opt->count() && (name == "width" || name == "height"))
                lc::setParam(settings, scene.camera, name, paramValues.at(name));
        std::vector<std::pair<std::string, std::string>> given;
        for (const auto& [name, opt] : paramOptions)
            if (opt->count() && name != "width" && name != "height") given.emplace_back(name, paramValues.at(name));
        // With a preset the flags go in before its derived settings, which
        // follow them (a light limit raised re-derives URP's tile width).
        if (optPreset && optPreset->count())
            lc::applyPreset(lc::enginePreset(presetName), settings, scene.camera, scene.lights.size(), given);
        else
            for (const auto& [name, value] : given) lc::setParam(settings, scene.camera, name, value);
        // A flag the chosen algorithm never reads is said, not silently dropped.
        const bool spots = std::any_of(scene.lights.begin(), scene.lights.end(),
                                       [](const lc::PointLight& l) { return l.isSpot(); });
        for (const auto& [name, value] : given)
            if (name != "tile" && !lc::paramAppliesTo(name, settings, spots))
                std::cerr << "lightcull: note: --" << name << " does not apply to "
                          << lc::toString(settings.algorithm)
                          << (settings.algorithm == lc::Algorithm::Raster && !settings.proxySlices &&
                                      (name == "cells" || name == "slicing" || name == "skip-empty")
                                  ? " with --proxy-depth tile"
                                  : "")
                          << " here; ignored\n";
    }

    std::unique_ptr<lc::CullBackend> openBackend() const {
        if (!backendName.empty()) return lc::makeBackend(backendName, device);
        // Default: Vulkan where this build has it and a device opens, else the CPU reference.
        const auto avail = lc::availableBackends();
        // A device the user named (--device, LIGHTCULL_DEVICE) is wanted, not
        // a default: when it does not open the run fails rather than timing
        // the CPU under the GPU's name.
        const char* env = std::getenv("LIGHTCULL_DEVICE");
        const bool named = !device.empty() || (env && *env);
        if (std::find(avail.begin(), avail.end(), "vulkan") != avail.end()) {
            try {
                return lc::makeBackend("vulkan", device);
            } catch (const lc::Error& e) {
                if (named) throw;
                std::cerr << "lightcull: note: no Vulkan device (" << oneLine(e.what()) << "), using the cpu backend\n";
            }
        } else if (named) {
            throw lc::SettingsError("device", "this build has no Vulkan backend");
        }
        return lc::makeBackend("cpu");
    }
};


// ---- bench -----------------------------------------------------------------

struct BenchOptions {
    int repeat = 10, warmup = 2;
    std::vector<std::string> sweeps; // KEY=V1,V2,...
    std::string jsonFile;
};

void addBenchOptions(CLI::App* cmd, BenchOptions& o) {
    cmd->add_option("--repeat", o.repeat, "Timed repeats per configuration (default: 10)")
        ->type_name("N")
        ->check(CLI::Range(1, 100000));
    cmd->add_option("--warmup", o.warmup, "Untimed runs before the repeats (default: 2)")
        ->type_name("N")
        ->check(CLI::Range(0, 100000));
    std::string params; // from the parameter table, so the help names every one
    for (const lc::ParamSpec& p : lc::cullParams()) params += std::string(params.empty() ? "" : ", ") + p.name;
    cmd->add_option("--sweep", o.sweeps,
                    "KEY=V1,V2,... run every value; several --sweep flags form a cross product. KEY: lights, "
                    "resolution (WxH), or any culling parameter (" + params + ")")
        ->type_name("KEY=V1,V2,...");
    cmd->add_option("--json", o.jsonFile, "Also write the results as JSON to FILE")->type_name("FILE");
}

struct Sweep {
    std::string key;
    std::vector<std::string> values;
};

std::vector<Sweep> parseSweeps(const std::vector<std::string>& specs) {
    std::vector<Sweep> sweeps;
    for (const std::string& spec : specs) {
        const auto eq = spec.find('=');
        if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size())
            throw lc::SettingsError("sweep", "expected KEY=V1,V2,..., got '" + spec + "'");
        Sweep sw{spec.substr(0, eq), {}};
        std::stringstream values(spec.substr(eq + 1));
        for (std::string v; std::getline(values, v, ',');) {
            if (v.empty()) throw lc::SettingsError("sweep", "empty value in '" + spec + "'");
            sw.values.push_back(v);
        }
        if (sw.key != "lights" && sw.key != "resolution") lc::cullParam(sw.key); // throws for unknown keys
        for (const Sweep& other : sweeps)
            if (other.key == sw.key) throw lc::SettingsError("sweep", "key '" + sw.key + "' swept twice");
        sweeps.push_back(std::move(sw));
    }
    return sweeps;
}

struct Stats {
    double median = 0, min = 0, max = 0;
};

Stats stats(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return {n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]), v.front(), v.back()};
}

nlohmann::json statsJson(const Stats& s) { return {{"median", s.median}, {"min", s.min}, {"max", s.max}}; }

// One sweep value applied to a configuration; `generate` false only checks a
// light count (generating a million lights to check it would be a run).
void applySweepValue(const SceneFlags& flags, lc::Scene& scene, lc::CullSettings& settings, const std::string& key,
                     const std::string& value, bool generate) {
    if (key == "lights") {
        long long n = 0;
        std::size_t used = 0;
        try {
            n = std::stoll(value, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used != value.size()) throw lc::SettingsError("sweep", "lights: not an integer: '" + value + "'");
        if (n < 0 || n > 1000000) throw lc::SettingsError("sweep", "lights: must be in 0..1000000, got " + value);
        if (generate) flags.replaceLights(scene, n);
    } else if (key == "resolution") {
        const auto x = value.find('x');
        if (x == std::string::npos) throw lc::SettingsError("sweep", "resolution: expected WxH, got '" + value + "'");
        lc::setParam(settings, scene.camera, "width", value.substr(0, x));
        lc::setParam(settings, scene.camera, "height", value.substr(x + 1));
    } else {
        lc::setParam(settings, scene.camera, key, value);
    }
}

int runBench(const SceneFlags& flags, const BenchOptions& opt) {
    const std::vector<Sweep> sweeps = parseSweeps(opt.sweeps);
    const lc::Scene base = flags.loadScene();
    lc::CullSettings baseSettings;
    lc::Scene baseWithParams = base;
    flags.applyParams(baseSettings, baseWithParams);
    // Every sweep value and the JSON's folder are checked before the first
    // run: a long sweep must not end in an error its first second could tell.
    for (const Sweep& sw : sweeps)
        for (const std::string& value : sw.values) {
            lc::Scene scene = baseWithParams;
            lc::CullSettings settings = baseSettings;
            try {
                applySweepValue(flags, scene, settings, sw.key, value, false);
                if (const std::string bad = settings.validate(); !bad.empty()) throw lc::SettingsError("settings", bad);
            } catch (const lc::SettingsError& e) {
                if (e.field() == "sweep") throw;
                throw lc::SettingsError("sweep", sw.key + "=" + value + ": " + e.what());
            }
        }
    if (!opt.jsonFile.empty()) {
        if (const std::string why = outputProblem([&] { lc::checkFileTarget(opt.jsonFile); }); !why.empty())
            throw lc::SettingsError("json", why);
    }
    std::unique_ptr<lc::CullBackend> backend = flags.openBackend();

    // The header comes with the first row: a command that fails at its one
    // configuration prints nothing on stdout (docs/CLI.md, errors).
    bool headerShown = false;
    const auto header = [&] {
        if (headerShown) return;
        headerShown = true;
        std::cout << "bench " << base.name << ": backend " << backend->name() << ", device " << backend->deviceName()
                  << ", timing " << backend->timingMethod() << ", " << opt.warmup << " warm-up + " << opt.repeat
                  << " timed runs per configuration (ms: median [min..max])\n";
    };

    nlohmann::json configs = nlohmann::json::array();
    std::vector<std::size_t> index(sweeps.size(), 0);
    // Configurations the device refuses (past one of its limits: raster's
    // slices over the binding range, too many tiles for a dispatch) are
    // rows of their own: the sweep goes on and keeps what it measured.
    std::size_t refused = 0, total = 0;
    std::string firstRefusal;
    // The next configuration of the cross product (the first sweep varies
    // fastest); false after the last.
    const auto next = [&] {
        std::size_t k = 0;
        while (k < sweeps.size() && ++index[k] == sweeps[k].values.size()) index[k++] = 0;
        return k < sweeps.size();
    };
    for (;;) {
        ++total;
        lc::Scene scene = baseWithParams;
        lc::CullSettings settings = baseSettings;
        nlohmann::json params = nlohmann::json::object();
        std::string label;
        for (std::size_t k = 0; k < sweeps.size(); ++k) {
            const std::string& key = sweeps[k].key;
            const std::string& value = sweeps[k].values[index[k]];
            applySweepValue(flags, scene, settings, key, value, true);
            params[key] = value;
            label += (label.empty() ? "" : " ") + key + "=" + value;
        }
        if (label.empty()) label = "(scene settings)";
        scene.validate();
        if (const std::string bad = settings.validate(); !bad.empty()) throw lc::SettingsError("settings", bad);

        const lc::Projection proj(scene.camera);
        const lc::TileGrid grid = lc::TileGrid::make(scene.camera.width, scene.camera.height, scene.camera.tileSize);
        const lc::ViewLights lights = lc::makeViewLights(scene);
        std::vector<double> depthMs, depthWallMs, depthCallMs, cullMs, cullWallMs, cullCallMs;
        std::size_t peakDeviceBytes = 0;
        lc::CullResult last;
        using Clock = std::chrono::steady_clock;
        const auto msSince = [](Clock::time_point t0) {
            return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        };
        lc::DepthPass pass;
        try {
            for (int i = 0; i < opt.warmup + opt.repeat; ++i) {
                const Clock::time_point d0 = Clock::now();
                pass = backend->depthPass(scene, proj);
                const double dc = msSince(d0);
                const lc::DepthImage& depth = pass.image;
                const double d = pass.ms, dw = pass.wallMs;
                // Peak device memory of the culling pass alone: what it allocates
                // beyond what is alive before it (its buffers, the staging copies
                // included; the depth image is the input, on the device already
                // when the backend rendered it).
                backend->resetPeakDeviceBytes();
                const std::size_t alive = backend->peakDeviceBytes();
                last = lc::CullResult();
                const Clock::time_point c0 = Clock::now();
                last = backend->cull(depth, proj, grid, lights, settings);
                const double cc = msSince(c0);
                peakDeviceBytes = std::max(peakDeviceBytes, backend->peakDeviceBytes() - alive);
                if (i >= opt.warmup) {
                    depthMs.push_back(d);
                    depthWallMs.push_back(dw);
                    depthCallMs.push_back(dc);
                    cullMs.push_back(last.timings.cullMs);
                    cullWallMs.push_back(backend->lastCullWallMs());
                    cullCallMs.push_back(cc);
                }
            }
        } catch (const lc::SettingsError& e) {
            // Every value was checked before the first run: this is the
            // device's refusal. Without a sweep it is the command's error.
            if (sweeps.empty()) throw;
            header();
            std::cout << label << ": refused: " << e.what() << "\n";
            configs.push_back({{"params", params}, {"refused", e.what()}});
            if (!refused++) firstRefusal = label + ": " + e.what();
            if (!next()) break;
            continue;
        }
        const Stats ds = stats(depthMs), dws = stats(depthWallMs), dcs = stats(depthCallMs),
                    cs = stats(cullMs), ws = stats(cullWallMs), ccs = stats(cullCallMs);
        header();
        std::cout << label << ": depth " << fmt("%.3f", ds.median) << " [" << fmt("%.3f", ds.min) << ".."
                  << fmt("%.3f", ds.max) << "] (wall " << fmt("%.3f", dws.median) << ", call "
                  << fmt("%.3f", dcs.median) << ", " << pass.trianglesDrawn << " of "
                  << pass.triangles << " triangles), cull " << fmt("%.3f", cs.median) << " ["
                  << fmt("%.3f", cs.min) << ".." << fmt("%.3f", cs.max) << "] (wall "
                  << fmt("%.3f", ws.median) << ", call " << fmt("%.3f", ccs.median) << "), " << last.entries()
                  << " entries, " << last.listCountTotal() << " lists, " << last.bytes() << " bytes (+"
                  << last.diagnosticBytes() << " diagnostic), " << last.volumeTests
                  << " volume tests, peak device " << peakDeviceBytes << " bytes\n";
        configs.push_back({{"params", params},
                           {"algorithm", lc::toString(settings.algorithm)},
                           {"test", lc::toString(settings.test)},
                           {"cells", settings.cells},
                           {"slicing", lc::toString(settings.slicing)},
                           {"width", scene.camera.width},
                           {"height", scene.camera.height},
                           {"tile_size", scene.camera.tileSize},
                           {"lights", lights.size()},
                           {"depth_ms", statsJson(ds)},
                           {"depth_wall_ms", statsJson(dws)},
                           {"depth_call_ms", statsJson(dcs)},
                           {"cull_ms", statsJson(cs)},
                           {"cull_wall_ms", statsJson(ws)},
                           {"cull_call_ms", statsJson(ccs)},
                           {"device_index_bits", backend->lastDeviceIndexBits()},
                           {"list_entries", last.entries()},
                           {"lists", last.listCountTotal()},
                           {"result_bytes", last.bytes()},
                           {"diagnostic_bytes", last.diagnosticBytes()},
                           {"volume_tests", last.volumeTests},
                           {"depth_bytes", std::uint64_t(scene.camera.width) * scene.camera.height * 4},
                           {"depth_triangles", pass.triangles},
                           {"depth_triangles_drawn", pass.trianglesDrawn},
                           {"peak_device_bytes", peakDeviceBytes}});
        if (!next()) break;
    }

    if (!opt.jsonFile.empty()) {
        const nlohmann::json doc = {{"scene", base.name},
                                    {"backend", backend->name()},
                                    {"device", backend->deviceName()},
                                    {"timing_method", backend->timingMethod()},
                                    {"repeat", opt.repeat},
                                    {"warmup", opt.warmup},
                                    {"configs", configs}};
        lc::writeFileAtomic(opt.jsonFile, doc.dump(2) + "\n");
        std::cout << "wrote " << opt.jsonFile << "\n";
    }
    if (refused)
        return fail(1, std::to_string(refused) + " of " + std::to_string(total) +
                           " configurations refused by the device (the first: " + firstRefusal + ")");
    return 0;
}

} // namespace

int main(int argc, char** argv) {
    CLI::App app{"lightcull: tiled and clustered light culling, measured against exact ground truth"};
    app.set_version_flag("--version", std::string("lightcull ") + LC_VERSION);
    app.require_subcommand(1, 1);

    app.add_subcommand("scenes", "List the built-in scenes with a description of each");

    CLI::App* run = app.add_subcommand(
        "run", "Run depth pre-pass, culling and ground truth on a scene; write summary.json, "
               "tiles.csv and heatmap.png into --out DIR");
    SceneFlags runFlags;
    runFlags.addTo(run);
    std::string outDir;
    bool noImageError = false;
    run->add_flag("--no-image-error", noImageError,
                  "Skip the shading pass and the Lambert image error (it costs pixels x lights); JSON gets null");
    bool shadedImages = false;
    run->add_flag("--shaded-images", shadedImages,
                  "Also write shaded_culled.png, shaded_all.png and shaded_diff.png (the backend's shading pass)");
    run->add_option("--out", outDir, "Folder to write the diagnostics into (written atomically; missing parent folders are made)")
        ->type_name("DIR")
        ->required();
    lcli::CustomFlags runCustom;
    runCustom.addToRun(run);
    std::string renderdocCapture;
    run->add_option("--renderdoc-capture", renderdocCapture,
                    "Also write a RenderDoc capture of the run's Vulkan work (depth pre-pass, culling, shading) to "
                    "FILE.rdc (needs librenderdoc; docs/RENDERDOC.md)")
        ->type_name("FILE");

    CLI::App* check = app.add_subcommand(
        "check", "Judge an engine's own light lists (a buffer dump or CSV) against ground truth on its depth buffer; "
                 "writes the same diagnostics as run");
    SceneFlags checkFlags;
    checkFlags.addTo(check);
    std::string checkLists, checkLayout = "fixed:64", checkRule = "tile", checkOut;
    check->add_option("--lists", checkLists, "The lists: raw little-endian 32-bit words in --layout, or .csv (list,light,...)")
        ->type_name("FILE");
    std::string checkCapture, checkDispatch, checkDescribe;
    check->add_option("--capture", checkCapture,
                      "A RenderDoc capture of the renderer's frame: lists, depth, lights and camera are read from it "
                      "at --dispatch, as --describe says (instead of --scene and --lists; docs/RENDERDOC.md)")
        ->type_name("FILE.rdc");
    check->add_option("--dispatch", checkDispatch,
                      "The culling dispatch in --capture: its event id, or text of its name or marker regions")
        ->type_name("EVENT|NAME");
    check->add_option("--describe", checkDescribe,
                      "JSON description of the renderer's light struct, camera, depth and list layout in --capture")
        ->type_name("FILE.json");
    check->add_option("--layout", checkLayout, "Layout of a raw dump: fixed:N, compact[:N] or bitmask (default fixed:64)")
        ->type_name("LAYOUT");
    check->add_option("--rule", checkRule, "Which list a pixel loops over: tile, halfz, froxel:N[:log|linear] or cells:N[:log|linear] (default tile)")
        ->type_name("RULE");
    lcli::CustomFlags checkDepth;
    checkDepth.addDepth(check);
    check->add_option("--out", checkOut, "Folder to write the diagnostics into")->type_name("DIR")->required();

    CLI::App* captureInfo = app.add_subcommand(
        "capture-info", "List a RenderDoc capture's dispatches and draws; with --dispatch, the bindings of one "
                        "dispatch (set, binding, kind, size, debug names)");
    std::string captureInfoFile, captureInfoDispatch;
    captureInfo->add_option("capture", captureInfoFile, "The capture (.rdc)")->type_name("FILE.rdc")->required();
    captureInfo->add_option("--dispatch", captureInfoDispatch, "A dispatch: its event id, or text of its name or markers")
        ->type_name("EVENT|NAME");

    CLI::App* bench = app.add_subcommand(
        "bench", "Time the depth pre-pass and the culling pass over repeats (median/min/max), "
                 "optionally sweeping parameters; no ground truth");
    SceneFlags benchFlags;
    benchFlags.addTo(bench);
    BenchOptions benchOptions;
    addBenchOptions(bench, benchOptions);

    lcli::ReportCommand report;
    report.add(app);

    lcli::HuntCommand hunt;
    hunt.add(app);

    CLI::App* explain = app.add_subcommand(
        "explain", "Why is a light in a tile's list, or why not: the algorithm's tests with their numbers and the "
                   "ground truth of the list's pixels");
    SceneFlags explainFlags;
    explainFlags.addTo(explain, "tile-size");
    std::string explainTile, explainLightText;
    int explainCell = -1;
    explain->add_option("--tile", explainTile, "The tile, as X,Y (0,0 is the top-left tile)")->type_name("X,Y")->required();
    explain->add_option("--cell", explainCell,
                        "The tile's sub-list: halfz 0 near / 1 far, clustered (and raster --proxy-depth slices) slice, cells:N cell "
                        "(default: the tile's list)")
        ->type_name("C");
    explain->add_option("--light", explainLightText, "The light: its index or its name")->type_name("I|NAME")->required();

    CLI::App* convert = app.add_subcommand(
        "convert", "Convert a scene between scene JSON, glTF 2.0 (.gltf) and binary glTF (.glb), by extension; "
                   "the output is written atomically");
    lcli::SceneSource convertIn;
    convertIn.addTo(convert, true);
    std::string convertOut;
    convert->add_option("out", convertOut, "File to write: .json, .gltf or .glb")->type_name("OUT")->required();

    // CLI11 reports a missing subcommand before an unknown word; name the word.
    if (argc > 1 && argv[1][0] != '-' && std::string(argv[1]) != "scenes" && std::string(argv[1]) != "run" &&
        std::string(argv[1]) != "bench" && std::string(argv[1]) != "report" &&
        std::string(argv[1]) != "convert" && std::string(argv[1]) != "check" &&
        std::string(argv[1]) != "explain" && std::string(argv[1]) != "hunt" &&
        std::string(argv[1]) != "capture-info")
        return fail(2, std::string("unknown command '") + argv[1] +
                           "' (commands: scenes, run, bench, report, convert, check, capture-info, explain, hunt; "
                           "see --help)");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e); // --help, --version
        const std::vector<CLI::App*> chosen = app.get_subcommands();
        return fail(2, plainParseError(e.what(), chosen.empty() ? std::string() : chosen.front()->get_name()));
    }

    try {
        if (app.got_subcommand("scenes")) {
            std::size_t w = 0;
            for (const auto& s : lc::builtinScenes()) w = std::max(w, s.name.size());
            for (const auto& s : lc::builtinScenes())
                std::cout << s.name << std::string(w + 2 - s.name.size(), ' ') << s.description
                          << (s.name == lc::kDefaultBuiltin ? " (default)" : "") << "\n";
            return 0;
        }

        if (app.got_subcommand("bench")) {
            if (!benchFlags.hasScene()) return fail(2, "bench: give --scene FILE or --builtin NAME");
            return runBench(benchFlags, benchOptions);
        }

        if (report.chosen()) return report.run();

        if (hunt.chosen()) return hunt.run();

        if (app.got_subcommand("convert")) {
            lcli::SceneSource::checkSceneExtension("OUT", convertOut); // before reading IN
            if (const std::string why = outputProblem([&] { lc::checkFileTarget(convertOut); }); !why.empty())
                return fail(2, "OUT: " + why);
            const lc::Scene scene = convertIn.load();
            lc::saveSceneAny(scene, convertOut);
            std::cout << "wrote " << convertOut << ": " << scene.triangleCount()
                      << (scene.triangleCount() == 1 ? " triangle, " : " triangles, ") << scene.lights.size()
                      << (scene.lights.size() == 1 ? " light, camera " : " lights, camera ") << lc::toString(scene.camera.projection) << " " << scene.camera.width << "x"
                      << scene.camera.height << "\n";
            return 0;
        }

        if (app.got_subcommand("explain")) {
            if (!explainFlags.hasScene()) return fail(2, "explain: give --scene FILE or --builtin NAME");
            lc::Scene scene = explainFlags.loadScene();
            lc::CullSettings settings;
            explainFlags.applyParams(settings, scene);
            unsigned tx = 0, ty = 0;
            char tail = 0;
            if (std::sscanf(explainTile.c_str(), "%u,%u%c", &tx, &ty, &tail) != 2)
                return fail(2, "--tile: expected X,Y, got '" + explainTile + "'");
            // Digits are an index (as tiles.csv names lights), anything else a
            // name; a light named with digits is reached by its index.
            std::uint32_t light = 0;
            const bool digits = !explainLightText.empty() && explainLightText.size() < 10 &&
                                explainLightText.find_first_not_of("0123456789") == std::string::npos;
            if (digits) {
                const unsigned long v = std::stoul(explainLightText);
                if (v >= scene.lights.size())
                    return fail(2, "--light: " + explainLightText + " is not a light index (the scene has " +
                                       std::to_string(scene.lights.size()) + " lights)");
                light = std::uint32_t(v);
                for (std::size_t i = 0; i < scene.lights.size(); ++i)
                    if (scene.lights[i].name == explainLightText && i != light)
                        std::cerr << "lightcull: note: --light " << explainLightText << " is light " << light
                                  << "; light " << i << " is named '" << explainLightText << "'\n";
            } else {
                bool byName = false;
                for (std::size_t i = 0; i < scene.lights.size(); ++i)
                    if (scene.lights[i].name == explainLightText) {
                        // Two lights of one name (glTF allows it): the index decides.
                        if (byName)
                            return fail(2, "--light: lights " + std::to_string(light) + " and " + std::to_string(i) +
                                               " are both named '" + explainLightText + "': give the index");
                        light = std::uint32_t(i);
                        byName = true;
                    }
                if (!byName) return fail(2, "--light: no light named '" + explainLightText + "' and not an index");
            }
            std::unique_ptr<lc::CullBackend> backend = explainFlags.openBackend();
            lc::RunOptions options;
            options.truthOptions.imageError = false;
            const lc::RunOutput run = lc::runPipeline(scene, settings, *backend, options);
            const lc::CullResult& r = run.result;
            if (tx >= r.grid.tilesX || ty >= r.grid.tilesY)
                return fail(2, "--tile: " + explainTile + " is outside the " + std::to_string(r.grid.tilesX) + "x" +
                                   std::to_string(r.grid.tilesY) + " tiles");
            const lc::Projection proj(scene.camera);
            const std::uint32_t list = r.listOf(r.grid.tileIndex(tx, ty), explainCell);
            const lc::Explanation e = lc::explainLight(run, proj, list, light);
            std::cout << "scene " << scene.name << ", " << r.grid.width << "x" << r.grid.height << ", backend "
                      << r.backend << ", tile " << tx << "," << ty << "\n"
                      << e.text(light < scene.lights.size() ? scene.lights[light].name : std::string());
            return 0;
        }

        if (app.got_subcommand("capture-info")) {
            if (captureInfoDispatch.empty()) {
                printCaptureActions(lc::readCaptureInfo(captureInfoFile));
                return 0;
            }
            printCaptureBindings(lc::readDispatchInfo(captureInfoFile, captureInfoDispatch));
            return 0;
        }

        if (app.got_subcommand("check") && !checkCapture.empty()) {
            if (checkFlags.hasScene() || !checkLists.empty())
                return fail(2, "check --capture reads the lights, camera and lists from the capture: drop --scene, "
                               "--builtin and --lists");
            if (checkDispatch.empty()) return fail(2, "check --capture: give --dispatch EVENT|NAME (lightcull capture-info lists them)");
            if (checkDescribe.empty())
                return fail(2, "check --capture: give --describe FILE.json (the light struct, camera, depth and list layout)");
            if (!checkDepth.depthFile.empty()) return fail(2, "--depth: check --capture reads the depth from the capture");
            if (const std::string f = checkFlags.givenCullingFlag(); !f.empty())
                return fail(2, f + ": has no effect on check --capture (the description says the tile and the list rule)");
            if (const std::string why = outputProblem([&] { lc::checkDiagnosticsFolder(checkOut); }); !why.empty())
                return fail(2, "--out: " + why);
            const lc::CaptureDescription description = lc::loadCaptureDescription(checkDescribe);
            lc::CaptureFrame frame = lc::loadCaptureFrame(checkCapture, checkDispatch, description);
            frame.scene.origin.command = commandLine(argc, argv);
            for (const std::string& line : frame.echo) std::cout << "read " << line << "\n";
            lc::CustomCullReport report;
            lc::RunOptions options;
            options.truthOptions.imageError = false;
            lc::RunOutput result = lc::checkCaptureFrame(frame, options, report);
            lc::CullSettings settings;
            settings.algorithm = result.result.algorithm;
            lc::exportDiagnostics(frame.scene, settings, result, checkOut);
            printSummary(frame.scene, settings, result, checkOut, "lists from a capture are not shaded");
            lcli::printCustomReport(result, frame.scene, lc::Projection(frame.scene.camera));
            return verdictExit(result);
        }

        if (app.got_subcommand("check")) {
            if (checkLists.empty()) return fail(2, "check: give --lists FILE (or --capture FILE.rdc)");
            if (!checkDispatch.empty() || !checkDescribe.empty())
                return fail(2, "--dispatch and --describe go with --capture");
            if (!checkFlags.hasScene()) return fail(2, "check: give --scene FILE or --builtin NAME (the scene the lists were culled for)");
            lc::Scene scene = checkFlags.loadScene();
            scene.origin.command = commandLine(argc, argv);
            lc::CullSettings settings;
            if (const std::string why = outputProblem([&] { lc::checkDiagnosticsFolder(checkOut); }); !why.empty())
                return fail(2, "--out: " + why);
            if (const std::string f = checkFlags.givenCullingFlag(); !f.empty())
                return fail(2, f + ": has no effect on check: the dump's lists are judged as they are (--rule says "
                                   "whose pixels read each list)");
            checkFlags.applyParams(settings, scene);
            const lc::Projection proj(scene.camera);
            lc::DepthPass pass;
            lc::DepthImage& depth = pass.image;
            std::unique_ptr<lc::CullBackend> backend;
            if (!checkDepth.depthFile.empty()) {
                depth = lc::loadDepthFile(checkDepth.depthFile, proj);
            } else {
                scene.validate();
                backend = checkFlags.openBackend();
                pass = backend->depthPass(scene, proj);
            }
            lc::CustomCullReport report;
            lc::RunOptions options;
            options.truthOptions.imageError = false;
            lc::RunOutput result = lc::checkListDump(scene, checkLists, lc::parseLayout(checkLayout),
                                                     lc::parseListSpec(checkRule), depth, options, report);
            // The lists are judged on this depth: say whose it is (backends'
            // rasterisers differ at a few edge pixels, and so can a verdict).
            if (backend) {
                result.depthReused = false;
                result.depthFrom = "pre-pass on " + backend->name() + " (" + backend->deviceName() + ")";
                result.result.timings.depthMs = pass.ms;
                result.result.depthTriangles = pass.triangles;
                result.result.depthTrianglesDrawn = pass.trianglesDrawn;
            } else {
                result.depthFrom = "depth file " + checkDepth.depthFile;
            }
            lc::exportDiagnostics(scene, settings, result, checkOut);
            printSummary(scene, settings, result, checkOut, "lists from a dump are not shaded");
            lcli::printCustomReport(result, scene, proj);
            return verdictExit(result);
        }

        if (!runFlags.hasScene()) return fail(2, "run: give --scene FILE or --builtin NAME");
        if (!runCustom.shader.empty())
            if (const std::string f = runFlags.givenCullingFlag(); !f.empty())
                return fail(2, f + ": has no effect with --shader: the shader culls (--layout and --lists say how "
                                   "its lists read)");
        // Fail before the (possibly long) run when the output cannot be written.
        if (const std::string why = outputProblem([&] { lc::checkDiagnosticsFolder(outDir); }); !why.empty())
            return fail(2, "--out: " + why);

        std::unique_ptr<lc::RenderDocCapture> capture;
        if (!renderdocCapture.empty()) {
            if (const std::string why = outputProblem([&] { lc::checkFileTarget(renderdocCapture); }); !why.empty())
                return fail(2, "--renderdoc-capture: " + why);
            // The output folder is replaced as a whole: a capture inside it
            // would be lost (or make the next run refuse the folder).
            namespace fs = std::filesystem;
            const auto inside = [](const fs::path& file, const fs::path& dir) {
                const fs::path f = fs::weakly_canonical(fs::absolute(file)), d = fs::weakly_canonical(fs::absolute(dir));
                const auto [a, b] = std::mismatch(d.begin(), d.end(), f.begin(), f.end());
                return a == d.end();
            };
            if (inside(renderdocCapture, outDir))
                return fail(2, "--renderdoc-capture: " + renderdocCapture + " is inside --out " + outDir +
                                   ", which each run replaces; write the capture beside it");
            if (runFlags.backendName == "cpu" && runCustom.shader.empty())
                return fail(2, "--renderdoc-capture: the cpu backend makes no Vulkan calls to capture; use --backend vulkan");
            // Before any Vulkan instance, so RenderDoc's layer is in each.
            capture = std::make_unique<lc::RenderDocCapture>(renderdocCapture, "lightcull " + commandLine(argc, argv));
        }

        lc::Scene scene = runFlags.loadScene();
        scene.origin.command = commandLine(argc, argv);
        lc::CullSettings settings;
        runFlags.applyParams(settings, scene);
        std::unique_ptr<lc::CullBackend> backend = runFlags.openBackend();
        if (capture && runCustom.shader.empty() && backend->name() != "vulkan")
            return fail(1, "--renderdoc-capture: no Vulkan device opened (backend " + backend->name() +
                               "), so there is nothing to capture");
        if (capture && !runCustom.shader.empty())
            capture->captureCustomShader(); // its own device, captured at its dispatch
        else if (capture)
            capture->start();

        lc::RunOptions options;
        options.truthOptions.imageError = !noImageError;
        options.keepShadedImages = shadedImages;
        if (shadedImages && noImageError) return fail(2, "--shaded-images needs the shading pass: drop --no-image-error");
        lc::DepthImage engineDepth;
        if (!runCustom.depthFile.empty()) {
            scene.validate();
            engineDepth = lc::loadDepthFile(runCustom.depthFile, lc::Projection(scene.camera));
            options.reuseDepth = &engineDepth;
        }
        const bool custom = !runCustom.shader.empty();
        lc::CustomCullReport report;
        lc::RunOutput result = custom ? lc::runCustomPipeline(scene, runCustom.shaderOptions(runFlags.device), *backend,
                                                              options, report, options.reuseDepth)
                                      : lc::runPipeline(scene, settings, *backend, options);
        if (capture) {
            capture->finish();
            std::cerr << "RenderDoc capture written to " << renderdocCapture << " ("
                      << (runCustom.shader.empty() ? "depth pre-pass, culling and shading" : "the shader's dispatch")
                      << ")\n";
        }
        if (options.reuseDepth) result.depthFrom = "depth file " + runCustom.depthFile;
        lc::exportDiagnostics(scene, settings, result, outDir);
        printSummary(scene, settings, result, outDir);
        if (custom) lcli::printCustomReport(result, scene, lc::Projection(scene.camera));
        return verdictExit(result);
    } catch (const lc::SettingsError& e) {
        // A bad value on the command line (docs/CLI.md: exit 2), named by the
        // flag that gave it where the parameter is one.
        std::string message = e.what();
        for (const CLI::App* sub : app.get_subcommands())
            if (sub->get_option_no_throw("--" + e.field()) && message.rfind(e.field() + ": ", 0) == 0) {
                message = "--" + message;
                break;
            }
        return fail(2, message);
    } catch (const lc::Error& e) {
        return fail(1, e.what());
    } catch (const std::exception& e) {
        return fail(1, e.what());
    }
}
