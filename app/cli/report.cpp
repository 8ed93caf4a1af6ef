// lightcull report (--builtin NAME | --scene FILE) [--lights N [--seed S]]
//                  [--backend NAME]... [--repeat N] [culling flags] --out DIR
#include "report.hpp"

#include "custom.hpp"

#include "culling/core/errors.hpp"
#include "culling/core/presets.hpp"
#include "culling/core/text.hpp"
#include "culling/diagnostics/report.hpp"
#include "culling/scene/scene_io.hpp"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <sstream>

namespace lcli {

namespace {

int usage(const std::string& message) {
    std::cerr << "lightcull: error: " << message << "\n";
    return 2;
}

std::vector<std::string> splitCommas(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream in(s);
    for (std::string v; std::getline(in, v, ',');) out.push_back(v);
    return out;
}

// "about 2 min 10 s", "about 40 s", "under a second".
std::string aboutTime(double seconds) {
    if (!(seconds >= 1)) return "under a second";
    const long s = std::lround(seconds);
    if (s < 60) return "about " + std::to_string(s) + " s";
    if (s < 3600) return "about " + std::to_string(s / 60) + " min " + std::to_string(s % 60) + " s";
    return "about " + std::to_string(s / 3600) + " h " + std::to_string(s % 3600 / 60) + " min";
}

} // namespace

void ReportCommand::add(CLI::App& app) {
    cmd_ = app.add_subcommand(
        "report", "Sweep algorithm x tile size x cells x slicing x sphere test (every culling parameter that "
                  "applies) on every backend; write report.csv, report.md and pareto.png into --out DIR");
    source_.addTo(cmd_);
    optLights_ = cmd_->add_option("--lights", lights_,
                                  "Replace the scene's lights with N generated ones (deterministic)")
                     ->type_name("N");
    cmd_->add_option("--seed", seed_, "Seed of the light generator used by --lights (default: 1)")
        ->type_name("S")
        ->needs(optLights_);
    cmd_->add_option("--spot-fraction", spotFraction_,
                     "Fraction of the --lights that are spot lights (0..1, default 0; outer angles 15..45 degrees, "
                     "random directions)")
        ->type_name("F")
        ->needs(optLights_);
    // Help text names the backends without opening a device: a device opened
    // here would be opened by every command (and before a RenderDoc capture).
    cmd_->add_option("--backend", backends_,
                     "Backend to sweep on, cpu or vulkan (repeatable; default: cpu, and vulkan where a device opens)")
        ->type_name("NAME");
    cmd_->add_option("--device", device_, "Vulkan device: index or name substring")->type_name("D");
    std::string presetNames;
    for (const lc::EnginePreset& p : lc::enginePresets()) presetNames += (presetNames.empty() ? "" : ", ") + p.name;
    cmd_->add_option("--preset", presets_,
                     "Run these engine presets side by side instead of the sweep (repeatable or comma-separated; "
                     "docs/ENGINES.md): misses by cause and the first setting change that keeps every light. NAME: " +
                         presetNames)
        ->type_name("NAME[,NAME...]");
    cmd_->add_flag("--presets", allPresets_, "Run every engine preset side by side instead of the sweep");
    CLI::Option* shaderOpt = cmd_->add_option("--shader", shaders_,
                     "A custom culling shader as one more row (repeatable; its first-line settings give layout and "
                     "lists; docs/CUSTOM_CULLING.md)")
        ->type_name("FILE");
    cmd_->add_option("--timeout-ms", timeoutMs_,
                     "Custom shaders: a dispatch running this long is a hang (default 10000)")
        ->type_name("MS")
        ->check(CLI::Range(1.0, 3600000.0))
        ->needs(shaderOpt);
    cmd_->add_option("--repeat", repeat_, "Timed culls and shades per configuration; medians reported (default: 3)")
        ->type_name("N")
        ->check(CLI::Range(1, 1000));
    cmd_->add_option("--warmup", warmup_, "Untimed culls and shades before those (default: 1)")
        ->type_name("N")
        ->check(CLI::Range(0, 1000));
    // One flag per culling parameter: it holds that parameter at one value
    // instead of sweeping it (tile and cells take a comma-separated list).
    for (const lc::ParamSpec& p : lc::cullParams()) {
        std::string help = p.name == "width" || p.name == "height"
                               ? "Camera " + p.name + " in pixels (default: the scene's)"
                               : "Hold " + p.name + " at this value instead of sweeping it";
        if (p.name == "tile") help = "Tile sizes to sweep, comma-separated (default: 8,16,32)";
        if (p.name == "cells") help = "Cell counts to sweep, comma-separated (default: 1,2,4,8,16,32)";
        CLI::Option* o = cmd_->add_option("--" + p.name, paramValues_[p.name], help);
        o->type_name(p.name == "tile" || p.name == "cells" ? "N[,N...]" : "VALUE");
        paramOptions_.emplace_back(p.name, o);
    }
    cmd_->add_option("--out", outDir_, "Folder to write into (written atomically; missing parent folders are made)")
        ->type_name("DIR")
        ->required();
}

int ReportCommand::run() {
    if (!source_.given()) return usage("report: give --scene FILE or --builtin NAME");
    // Before the sweep: a folder the report may not replace is a bad --out.
    try {
        lc::checkReportFolder(outDir_);
    } catch (const lc::Error& e) {
        return usage(std::string("--out: ") + e.what());
    }

    lc::Scene scene = source_.load();
    if (optLights_->count()) {
        if (lights_ < 0 || lights_ > 1000000)
            throw lc::SettingsError("lights", "must be in 0..1000000, got " + std::to_string(lights_));
        lc::LightGenSettings gen = lc::defaultLightGen(scene, std::uint32_t(lights_), seed_);
        gen.spotFraction = spotFraction_; // generateLights refuses values outside [0, 1]
        scene.lights = lc::generateLights(gen);
    }

    lc::ReportOptions options;
    options.device = device_;
    // The same file however it is reached (./, an absolute path, a link).
    const auto same = [](const std::string& a, const std::string& b) {
        std::error_code ec;
        return std::filesystem::equivalent(a, b, ec) ||
               std::filesystem::path(a).lexically_normal() == std::filesystem::path(b).lexically_normal();
    };
    for (std::size_t i = 0; i < shaders_.size(); ++i) {
        const std::string& sh = shaders_[i];
        for (std::size_t j = 0; j < i; ++j)
            if (same(shaders_[j], sh)) return usage("--shader: " + sh + " is given twice");
        lc::CustomShaderOptions so = lc::shaderOptionsFromFile(sh);
        so.timeoutMs = timeoutMs_;
        so.device = device_;
        options.shaders.push_back(std::move(so));
    }
    options.repeat = repeat_;
    options.warmup = warmup_;
    for (const std::string& b : backends_)
        for (const std::string& name : splitCommas(b)) {
            // A misspelt name is the command line's fault (one that names a
            // backend this machine cannot open is skipped with a note).
            if (name != "cpu" && name != "vulkan")
                return usage("--backend: unknown backend '" + name + "' (cpu or vulkan)");
            options.backends.push_back(name);
        }
    lc::CullSettings scratch;
    for (const auto& [name, opt] : paramOptions_) {
        if (!opt->count()) continue;
        const std::string& value = paramValues_.at(name);
        if (name == "width" || name == "height") {
            lc::setParam(scratch, scene.camera, name, value);
        } else if (name == "tile" || name == "cells") {
            std::vector<std::uint32_t>& list = name == "tile" ? options.tileSizes : options.cellCounts;
            list.clear();
            for (const std::string& v : splitCommas(value)) {
                lc::Camera c;
                lc::setParam(scratch, c, name, v); // validates against the table's range
                list.push_back(std::uint32_t(std::stoul(v)));
            }
            if (list.empty()) throw lc::SettingsError(name, "give at least one value");
        } else {
            options.fixed[name] = value;
        }
    }

    // Each preset once, in the order named (--presets: all of them).
    const auto addPreset = [&](const std::string& name) {
        if (std::find(options.presets.begin(), options.presets.end(), name) == options.presets.end())
            options.presets.push_back(name);
    };
    if (allPresets_ && !presets_.empty())
        return usage("--presets runs every preset and --preset names the ones to run: give one of the two");
    if (allPresets_)
        for (const lc::EnginePreset& p : lc::enginePresets()) addPreset(p.name);
    for (const std::string& p : presets_)
        for (const std::string& name : splitCommas(p)) addPreset(lc::enginePreset(name).name);
    if (!options.presets.empty()) {
        for (const auto& [name, opt] : paramOptions_)
            if (opt->count() && name != "width" && name != "height")
                return usage("--" + name + ": has no effect with --preset/--presets: each preset sets the culling "
                             "(run --preset NAME --" + name + " to change one)");
        if (!shaders_.empty()) return usage("--shader: a custom shader is not a preset; run the two reports apart");
    }

    // Progress on stderr: on a terminal one line rewritten after each
    // configuration (cut to the terminal's width, so it never wraps),
    // elsewhere (a log, TERM=dumb) a line at each tenth and the last. What
    // is left is estimated at the pace of the last tenth of the
    // configurations done (at least one), not counting the first (which also
    // opened the backend and worked out what the rows share): the count and
    // the first estimate come after the second configuration, and the
    // estimate follows a change of pace (the second backend's rows).
    const char* term = std::getenv("TERM");
    const bool tty = ::isatty(STDERR_FILENO) && !(term && std::string(term) == "dumb");
    std::size_t columns = 80;
    if (winsize ws{}; tty && ::ioctl(STDERR_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0) columns = ws.ws_col;
    std::vector<std::chrono::steady_clock::time_point> finished; // of configuration 1, 2, ...
    std::size_t tenthsShown = 0;
    const auto plural = [](std::size_t n) { return lc::countOf(n, "configuration", "configurations"); };
    const auto clearLine = [&] {
        if (tty) std::cerr << "\r\033[K" << std::flush;
    };
    lc::Report report;
    try {
        report = lc::runReport(scene, options, [&](std::size_t done, std::size_t total, const std::string& label) {
            finished.push_back(std::chrono::steady_clock::now());
            std::string left; // ", about 1 min 5 s left"
            if (done > 1 && done < total) {
                const std::size_t span = std::clamp<std::size_t>(done / 10, 1, done - 1);
                const double pace =
                    std::chrono::duration<double>(finished[done - 1] - finished[done - 1 - span]).count() /
                    double(span);
                left = ", " + aboutTime(pace * double(total - done)) + " left";
            }
            if (done == std::min<std::size_t>(2, total)) {
                clearLine();
                std::cerr << "report: " << plural(total) << left << "\n";
            }
            const std::size_t tenths = done * 10 / total;
            if (tty) {
                std::string line = "[" + std::to_string(done) + "/" + std::to_string(total) + left + "] " + label;
                if (line.size() >= columns) line.resize(columns - 1);
                std::cerr << "\r" << line << "\033[K" << std::flush;
            } else if (done == total || (done > 2 && tenths > tenthsShown)) {
                std::cerr << "[" << done << "/" << total << "]" << left << "\n";
            }
            tenthsShown = tenths;
        });
    } catch (...) {
        clearLine(); // the error's line starts on a clean line
        throw;
    }
    clearLine();
    lc::writeReport(report, outDir_);

    std::cout << "report " << report.sceneName << ": " << report.width << "x" << report.height << ", "
              << report.lights << (report.lights == 1 ? " light, " : " lights, ") << plural(report.rows.size()) << "\n";
    for (const auto& [backend, device] : report.backendDevices) std::cout << "backend " << backend << ": " << device << "\n";
    for (const std::string& n : report.notes) std::cout << "note: " << n << "\n";
    std::uint64_t fnRows = 0;
    for (const lc::ReportRow& r : report.rows) fnRows += r.falseNegatives > 0;
    // Only a configuration that misses no light is a candidate.
    const lc::ReportRow* fastest = nullptr;
    for (const lc::ReportRow& r : report.rows)
        if (r.falseNegatives == 0 && (!fastest || r.totalMs < fastest->totalMs)) fastest = &r;
    if (fastest) {
        char buf[256];
        std::snprintf(buf, sizeof buf,
                      "fastest without false negatives: %s %s, total %.3f ms (cull %.3f + shade %.3f), efficiency %.4f\n",
                      fastest->config.backend.c_str(), fastest->config.label().c_str(), fastest->totalMs,
                      fastest->cullMs, fastest->shadeMs, fastest->efficiency);
        std::cout << buf;
    } else if (!report.rows.empty()) {
        std::cout << "fastest without false negatives: none (every configuration misses lights)\n";
    }
    std::cout << "configurations with false negatives: " << fnRows << "\n"
              << "wrote " << outDir_ << "/report.csv, report.md, pareto.png\n";
    return 0;
}

} // namespace lcli
