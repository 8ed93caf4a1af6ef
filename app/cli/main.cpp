// lightcull: the command-line front end of the culling library.
//
//   lightcull scenes
//   lightcull run (--scene FILE.json | --builtin NAME) [culling flags] [--lights N [--seed S]]
//                 [--backend cpu|vulkan] [--device D] [--no-image-error] --out DIR
//
// The culling flags are generated from lc::cullParams(), the one parameter
// table (see docs/CLI.md). Errors print one line on stderr and exit non-zero:
// 2 for a bad command line, 1 for anything that failed while running.

#include "culling/errors.hpp"
#include "culling/export.hpp"
#include "culling/params.hpp"
#include "culling/pipeline.hpp"
#include "culling/scene_io.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
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

void printSummary(const lc::Scene& scene, const lc::CullSettings& settings, const lc::RunOutput& run,
                  const std::string& out) {
    const lc::CullResult& r = run.result;
    const lc::Metrics& m = run.truth.metrics;
    std::cout << "scene " << scene.name << ": " << r.grid.width << "x" << r.grid.height << ", tile "
              << r.grid.tileSize << " (" << r.grid.tilesX << "x" << r.grid.tilesY << " tiles), "
              << run.lights.size() << " lights\n"
              << "algorithm " << lc::toString(settings.algorithm) << ", test "
              << lc::toString(settings.test) << ", cells " << settings.cells << ", slicing "
              << lc::toString(settings.slicing) << ", backend " << r.backend << " (" << r.device << ")\n"
              << "false negatives " << m.falseNegatives << ", efficiency " << fmt("%.4f", m.efficiency)
              << " (exact work " << m.exactWork << " / shading work " << m.shadingWork << ")\n"
              << "lists " << r.listCountTotal() << ", entries " << r.entries() << ", mean list "
              << fmt("%.2f", m.meanList) << ", max list " << m.maxList << ", " << m.resultBytes
              << " bytes\n";
    if (m.imageErrorComputed)
        std::cout << "image error: rmse " << fmt("%.6g", m.imageRmse) << ", max " << fmt("%.6g", m.imageMaxError) << "\n";
    else
        std::cout << "image error: not computed (--no-image-error)\n";
    std::cout << "times: depth " << ms(r.timings.depthMs) << ", cull " << ms(r.timings.cullMs)
              << ", ground truth " << ms(r.timings.groundTruthMs) << " (" << r.timingMethod << ")\n"
              << "wrote " << out << "/summary.json, tiles.csv, heatmap.png\n";
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
    std::string sceneFile, builtin, outDir, backendName, device;
    long long lightCount = -1;
    unsigned long long seed = 1;
    bool noImageError = false;
    CLI::Option* optScene = run->add_option("--scene", sceneFile, "Scene JSON file to load")->type_name("FILE.json");
    CLI::Option* optBuiltin =
        run->add_option("--builtin", builtin, "Built-in scene to use (see `lightcull scenes`)")->type_name("NAME");
    optScene->excludes(optBuiltin);

    // One flag per culling parameter, straight from the parameter table.
    std::map<std::string, std::string> paramValues;
    std::vector<std::pair<std::string, CLI::Option*>> paramOptions;
    for (const lc::ParamSpec& p : lc::cullParams()) {
        CLI::Option* o = run->add_option("--" + p.name, paramValues[p.name], paramDescription(p));
        o->type_name(p.type == lc::ParamType::Int ? "INT" : p.type == lc::ParamType::Bool ? "BOOL" : "CHOICE");
        paramOptions.emplace_back(p.name, o);
    }
    CLI::Option* optLights = run->add_option(
        "--lights", lightCount, "Replace the scene's lights with N generated ones (deterministic, placed in the scene's bounds)");
    optLights->type_name("N");
    run->add_option("--seed", seed, "Seed of the light generator used by --lights (default: 1)")
        ->type_name("S")
        ->needs(optLights);
    std::string backendHelp = "Backend running depth and culling: ";
    for (const std::string& b : lc::availableBackends()) backendHelp += b + " ";
    backendHelp += "(default: vulkan where available, else cpu)";
    run->add_option("--backend", backendName, backendHelp)->type_name("NAME");
    run->add_option("--device", device, "Vulkan device: index or name substring (default: LIGHTCULL_DEVICE, else the first discrete GPU)")
        ->type_name("D");
    run->add_flag("--no-image-error", noImageError,
                  "Skip the Lambert image error (it costs pixels x lights); JSON gets null");
    run->add_option("--out", outDir, "Folder to write the diagnostics into (written atomically; its parent must exist)")
        ->type_name("DIR")
        ->required();

    // CLI11 reports a missing subcommand before an unknown word; name the word.
    if (argc > 1 && argv[1][0] != '-' && std::string(argv[1]) != "scenes" && std::string(argv[1]) != "run")
        return fail(2, std::string("unknown command '") + argv[1] + "' (commands: scenes, run; see --help)");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e); // --help, --version
        return fail(2, e.what());
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

        if (sceneFile.empty() && builtin.empty())
            return fail(2, "run: give --scene FILE.json or --builtin NAME");
        {
            // Fail before the (possibly long) run when the output cannot be written.
            namespace fs = std::filesystem;
            fs::path target = fs::path(outDir).lexically_normal();
            if (!target.has_filename()) target = target.parent_path();
            fs::path parent = target.parent_path();
            if (parent.empty()) parent = ".";
            std::error_code ec;
            if (!fs::is_directory(parent, ec))
                return fail(2, "--out: parent folder " + parent.string() + " of " + outDir + " does not exist");
        }

        lc::Scene scene = sceneFile.empty() ? lc::makeBuiltinScene(builtin) : lc::loadSceneFile(sceneFile);
        if (optLights->count()) {
            if (lightCount < 0 || lightCount > 1000000)
                throw lc::SettingsError("lights", "must be in 0..1000000, got " + std::to_string(lightCount));
            scene.lights = lc::generateLights(lc::defaultLightGen(scene, std::uint32_t(lightCount), seed));
        }
        lc::CullSettings settings;
        for (const auto& [name, opt] : paramOptions)
            if (opt->count()) lc::setParam(settings, scene.camera, name, paramValues[name]);

        std::unique_ptr<lc::CullBackend> backend;
        if (backendName.empty()) {
            // Default: Vulkan where this build has it and a device opens, else the CPU reference.
            const auto avail = lc::availableBackends();
            if (std::find(avail.begin(), avail.end(), "vulkan") != avail.end()) {
                try {
                    backend = lc::makeBackend("vulkan", device);
                } catch (const lc::Error& e) {
                    std::cerr << "lightcull: note: no Vulkan device (" << oneLine(e.what())
                              << "), using the cpu backend\n";
                }
            }
            if (!backend) backend = lc::makeBackend("cpu");
        } else {
            backend = lc::makeBackend(backendName, device);
        }

        lc::RunOptions options;
        options.truthOptions.imageError = !noImageError;
        const lc::RunOutput result = lc::runPipeline(scene, settings, *backend, options);
        lc::exportDiagnostics(scene, settings, result, outDir);
        printSummary(scene, settings, result, outDir);
        return 0;
    } catch (const lc::Error& e) {
        return fail(1, e.what());
    } catch (const std::exception& e) {
        return fail(1, e.what());
    }
}
