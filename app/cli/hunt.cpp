// lightcull hunt [--scene FILE | --builtin NAME] [culling flags | --shader FILE ...]
//                [--seed S] [--trials N] [--budget SECONDS] [--vary DIMS] [--overflow] --out DIR
#include "hunt.hpp"

#include "culling/core/errors.hpp"
#include "culling/core/params.hpp"
#include "culling/diagnostics/hunt.hpp"
#include "culling/scene/gltf_io.hpp"
#include "culling/scene/scene_io.hpp"

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

namespace fs = std::filesystem;

namespace lcli {

namespace {

// A whole number in [lo, hi] written in digits (CLI11 would wrap "-1" and
// clamp 2^64 into an unsigned option).
CLI::Validator wholeNumber(unsigned long long lo, unsigned long long hi) {
    return CLI::Validator(
        [lo, hi](std::string& v) -> std::string {
            const std::string range = "a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
            if (v.empty() || v.size() > 20 || v.find_first_not_of("0123456789") != std::string::npos)
                return "must be " + range + ", got '" + v + "'";
            errno = 0;
            const unsigned long long x = std::strtoull(v.c_str(), nullptr, 10);
            if (errno == ERANGE || x < lo || x > hi) return "must be " + range + ", got '" + v + "'";
            return {};
        },
        "N");
}

// Ctrl+C (SIGINT) or SIGTERM during a hunt: the hunt stops at the next
// trial (the shrinking keeps what it has) and writes what it covered or
// found, instead of dying with nothing written. A second signal ends it
// at once.
lc::CancelToken gInterrupted;
extern "C" void onInterrupt(int sig) {
    if (gInterrupted.cancelled.exchange(true)) {
        std::signal(sig, SIG_DFL);
        std::raise(sig);
    }
}
struct InterruptScope {
    InterruptScope() {
        std::signal(SIGINT, onInterrupt);
        std::signal(SIGTERM, onInterrupt);
    }
    ~InterruptScope() {
        std::signal(SIGINT, SIG_DFL);
        std::signal(SIGTERM, SIG_DFL);
    }
};

int usage(const std::string& message) {
    std::cerr << "lightcull: error: " << message << "\n";
    return 2;
}

} // namespace

void HuntCommand::add(CLI::App& app) {
    cmd_ = app.add_subcommand(
        "hunt", "Search random small trials (camera, projection, screen, lights, spots, scene) for one where the "
                "culling misses a light; shrink it and write the repro into --out DIR (exit 3 when found)");
    source_.addTo(cmd_);
    for (const lc::ParamSpec& p : lc::cullParams()) {
        if (p.name == "width" || p.name == "height") continue; // the hunt varies the screen
        CLI::Option* o = cmd_->add_option("--" + p.name, paramValues_[p.name],
                                          p.name == "tile" ? "Tile size when the screen is not varied (default: the scene's)"
                                                           : p.help + " (default: " + p.defaultValue + ")");
        o->type_name(p.type == lc::ParamType::Int    ? "INT"
                     : p.type == lc::ParamType::Bool ? "BOOL"
                     : p.type == lc::ParamType::Real ? "REAL"
                                                     : "CHOICE");
        paramOptions_.emplace_back(p.name, o);
    }
    {
        std::string names;
        for (const lc::EnginePreset& p : lc::enginePresets()) names += (names.empty() ? "" : ", ") + p.name;
        cmd_->add_option("--preset", preset_,
                         "Hunt an engine's culling (docs/ENGINES.md): each trial culled with the preset's settings "
                         "for its screen and light count, as the engine derives them; culling flags given beside "
                         "it override it. NAME: " + names)
            ->type_name("NAME");
    }
    CLI::Option* s = cmd_->add_option("--shader", shader_,
                                      "Hunt in your own culling shader instead of a built-in algorithm "
                                      "(docs/CUSTOM_CULLING.md)")
                         ->type_name("FILE");
    cmd_->add_option("--layout", layout_, "Custom shader: fixed:N, compact[:N] or bitmask (default: its first line)")
        ->type_name("LAYOUT")
        ->needs(s);
    cmd_->add_option("--lists", lists_, "Custom shader: tile, halfz, froxel:N[:log|linear], cells:N[:log|linear]")
        ->type_name("RULE")
        ->needs(s);
    cmd_->add_flag("--no-validation", noValidation_, "Custom shader: without the Khronos validation layer")->needs(s);
    cmd_->add_option("--timeout-ms", timeoutMs_, "Custom shader: a dispatch running this long is a hang (default 10000)")
        ->type_name("MS")
        ->check(CLI::Range(1.0, 3600000.0))
        ->needs(s);
    searchOptions_.push_back(
        cmd_->add_option("--seed", seed_, "Seed of the search: the same seed gives the same trials (default: 1)")
            ->type_name("S")
            ->check(wholeNumber(0, 18446744073709551615ull)));
    searchOptions_.push_back(
        cmd_->add_option("--trials", trials_, "Stop after N trials (default: 200 unless --budget is given)")
            ->type_name("N")
            ->check(wholeNumber(1, 1000000000000ull)));
    searchOptions_.push_back(cmd_->add_option("--budget", budget_, "Stop after this many seconds")
                                 ->type_name("SECONDS")
                                 ->check(CLI::Validator(
                                     [](std::string& v) -> std::string {
                                         char* end = nullptr;
                                         const double x = std::strtod(v.c_str(), &end);
                                         if (v.empty() || *end || !(x > 0 && x <= 1e7))
                                             return "must be a number of seconds in (0, 10000000], got '" + v + "'";
                                         return {};
                                     },
                                     "SECONDS")));
    searchOptions_.push_back(
        cmd_->add_option("--vary", vary_,
                         "What trials vary, comma-separated: camera, projection, screen, lights, spots, scene "
                         "(default: all)")
            ->type_name("DIMS"));
    CLI::Option* path =
        cmd_->add_option("--path", path_,
                         "Judge every frame of a camera path instead of random trials: a glTF file's camera "
                         "animation or a JSON list of cameras (docs/FORMATS.md); writes path.csv and path.svg")
            ->type_name("FILE");
    cmd_->add_option("--fps", fps_, "--path from glTF: frames per second of the animation's sampling (default 30)")
        ->type_name("N")
        ->check(CLI::Range(1e-3, 1000.0))
        ->needs(path);
    cmd_->add_option("--animation", animation_, "--path from glTF: the animation (name or index; default: the first "
                                                "that moves the camera)")
        ->type_name("NAME")
        ->needs(path);
    cmd_->add_flag("--overflow", overflow_,
                   "A list over the custom layout's declared capacity is a failure too (default: counted apart)");
    cmd_->add_option("--backend", backend_,
                     "Backend of the depth pre-pass (and of a built-in algorithm's culling): cpu or vulkan "
                     "(default: vulkan where a device opens, else cpu)")
        ->type_name("NAME");
    cmd_->add_option("--device", device_, "Vulkan device: index or name substring")->type_name("D");
    cmd_->add_option("--out", outDir_, "Folder for the repro (scene.json, scene.glb, repro.sh, summary.json, verdict.txt)")
        ->type_name("DIR")
        ->required();
}

int HuntCommand::run() {
    lc::HuntOptions options;
    options.seed = seed_;
    options.vary = lc::parseHuntDims(vary_);
    if (options.vary == 0) return usage("--vary: name at least one of camera, projection, screen, lights, spots, scene");
    options.maxSeconds = budget_;
    options.maxTrials = trials_ ? trials_ : budget_ > 0 ? 0 : 200;
    options.overflowIsFailure = overflow_;
    lc::Camera scratchCamera;
    std::vector<std::string> cullingFlags; // for the repro command
    for (const auto& [name, opt] : paramOptions_) {
        if (!opt->count()) continue;
        if (!shader_.empty() && name != "tile")
            return usage(opt->get_name() + ": has no effect with --shader: the shader culls");
        lc::setParam(options.settings, scratchCamera, name, paramValues_.at(name));
        if (!preset_.empty()) options.presetOverrides.emplace_back(name, paramValues_.at(name));
    }
    if (!preset_.empty()) {
        if (!shader_.empty()) return usage("--preset: has no effect with --shader: the shader culls");
        try {
            options.preset = &lc::enginePreset(preset_);
        } catch (const lc::Error& e) {
            return usage(e.what());
        }
    }
    if (const std::string why = lc::huntOutputProblem(outDir_); !why.empty()) return usage("--out: " + why);

    if (!path_.empty())
        for (const CLI::Option* o : searchOptions_)
            if (o->count())
                return usage(o->get_name() + ": has no effect with --path: every frame of the path is judged");

    std::optional<lc::Scene> base;
    if (source_.given()) base = source_.load();
    else if (!path_.empty() && lc::isGltfPath(path_)) base = lc::loadSceneAny(path_);
    else if (!path_.empty())
        return usage("--path: give the scene (--scene or --builtin): a JSON camera path holds only cameras");
    if (base && path_.empty() && options.vary == lc::HuntSceneDim)
        return usage("--vary scene: with --scene or --builtin every trial keeps that scene's meshes; vary something "
                     "else, or leave out the scene to hunt in generated ones");
    if (base) {
        if (path_.empty()) options.vary &= ~unsigned(lc::HuntSceneDim); // the given scene's meshes stay
        base->validate();
        if (paramOptions_.size() && std::any_of(paramOptions_.begin(), paramOptions_.end(), [](const auto& p) {
                return p.first == "tile" && p.second->count();
            }))
            base->camera.tileSize = scratchCamera.tileSize;
        options.baseScene = &*base;
    }
    if (!shader_.empty()) {
        lc::CustomShaderOptions so = lc::shaderOptionsFromFile(shader_, layout_, lists_);
        so.device = device_;
        so.validation = !noValidation_;
        so.timeoutMs = timeoutMs_;
        options.shader = so;
    }

    std::unique_ptr<lc::CullBackend> backend;
    if (!backend_.empty()) {
        backend = lc::makeBackend(backend_, device_);
    } else {
        const auto avail = lc::availableBackends();
        if (std::find(avail.begin(), avail.end(), "vulkan") != avail.end()) {
            try {
                backend = lc::makeBackend("vulkan", device_);
            } catch (const lc::Error& e) {
                if (!device_.empty()) throw;
                std::cerr << "lightcull: note: no Vulkan device, using the cpu backend\n";
            }
        }
        if (!backend) backend = lc::makeBackend("cpu");
    }

    if (!path_.empty()) return runPath(options, *base, *backend);

    options.progress = [](const lc::HuntCoverage& c, double seconds) {
        std::fprintf(stderr, "hunt: %llu trials in %.1f s, %.1f trials/s; covered: %s\n",
                     static_cast<unsigned long long>(c.trials), seconds, seconds > 0 ? double(c.trials) / seconds : 0.0,
                     c.text().c_str());
    };
    options.cancel = &gInterrupted;
    const InterruptScope interrupts;
    const lc::HuntResult result = lc::hunt(options, *backend);
    if (result.cancelled || gInterrupted.cancelled)
        std::cerr << "lightcull: interrupted: writing what the hunt covered" << (result.failure ? " and found" : "")
                  << "\n";

    if (result.firstOverCapacityTrial)
        std::cout << "over capacity (not a failure without --overflow): " << result.coverage.overCapacity
                  << " trials, the first trial " << *result.firstOverCapacityTrial << "\n";
    const std::string command = lc::writeHuntRepro(result, options, *backend, outDir_, device_);
    if (!result.failure) {
        std::cout << lc::huntNoMissText(result, options);
        return gInterrupted.cancelled ? 130 : 0; // interrupted: not the clean pass a CI job may read 0 as
    }
    const lc::HuntFailure& f = *result.failure;
    const fs::path out(outDir_);
    // The verdict as written (it says so when the repro did not fail again).
    std::ostringstream verdict;
    verdict << std::ifstream(out / "verdict.txt").rdbuf();
    char took[32];
    std::snprintf(took, sizeof took, "%.1f", result.seconds);
    std::string wrote;
    for (const char* name : {"scene.json", "scene.glb", "repro.sh", "studio.sh", "summary.json", "verdict.txt", "run"})
        if (fs::exists(out / name))
            wrote += (wrote.empty() ? "" : ", ") + std::string(name) + (fs::is_directory(out / name) ? "/" : "");
    std::cout << "COUNTEREXAMPLE after " << f.trial + 1 << (f.trial ? " trials (" : " trial (") << took << " s):\n"
              << verdict.str() << "repro: " << (out / "repro.sh").string() << "  (" << command << ")\n"
              << "wrote " << outDir_ << "/" << wrote << "\n";
    std::cerr << "lightcull: the culling fails the hunt: " << f.verdict.property << " (exit 3)\n";
    return 3;
}

int HuntCommand::runPath(lc::HuntOptions& options, const lc::Scene& scene, lc::CullBackend& backend) {
    const lc::CameraPath path = lc::loadCameraPath(path_, scene.camera, fps_, animation_, lc::kCameraPathMaxFrames,
                                                     lc::isGltfPath(path_) ? source_.gltf.camera : std::string());
    std::cerr << "hunt: " << path.description << "\n";
    if (scene.lights.empty())
        std::cerr << "lightcull: warning: the scene has no lights: no frame can miss one\n";
    options.progress = [n = path.frames.size()](const lc::HuntCoverage& c, double seconds) {
        std::fprintf(stderr, "hunt: frame %llu of %zu in %.1f s, %.1f frames/s\n",
                     static_cast<unsigned long long>(c.trials), n, seconds,
                     seconds > 0 ? double(c.trials) / seconds : 0.0);
    };
    options.cancel = &gInterrupted;
    const InterruptScope interrupts;
    const lc::HuntPathResult result = lc::huntPath(options, scene, path, backend);
    const std::string command = lc::writeHuntRepro(lc::huntResultOf(result), options, backend, outDir_, device_);
    lc::writeHuntPathReport(result, path, outDir_);
    const fs::path out(outDir_);
    std::cout << "path: " << result.frames.size() << " frames, " << result.failingFrames << " failing; per frame: "
              << (out / "path.csv").string() << ", plot: " << (out / "path.svg").string() << "\n";
    if (!result.failure) {
        std::cout << lc::huntNoMissText(lc::huntResultOf(result), options);
        return gInterrupted.cancelled ? 130 : 0;
    }
    const std::string verdict = lc::huntVerdictText(*result.failure, options);
    std::cout << "COUNTEREXAMPLE at frame " << *result.worst << " (the worst):\n"
              << verdict << "repro: " << (out / "repro.sh").string() << "  (" << command << ")\n";
    std::cerr << "lightcull: the culling fails along the path: " << result.failure->verdict.property << " (exit 3)\n";
    return 3;
}

} // namespace lcli
