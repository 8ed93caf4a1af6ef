#pragma once
// `lightcull run --shader FILE` and `lightcull check --lists FILE`: a
// renderer's own culling judged like a built-in algorithm
// (docs/CUSTOM_CULLING.md). The flags live here; main.cpp runs the commands.
#include "culling/custom/custom_cull.hpp"
#include "culling/core/errors.hpp"

#include <CLI/CLI.hpp>

#include <fstream>
#include <iostream>
#include <string>

namespace lcli {

struct CustomFlags {
    std::string shader, layout, lists, entry, depthFile;
    bool noValidation = false;
    double timeoutMs = 10000;
    CLI::Option *optLayout = nullptr, *optLists = nullptr, *optEntry = nullptr;

    // run: --shader, --layout, --lists, --entry, --no-validation, --timeout-ms, --depth.
    void addToRun(CLI::App* cmd) {
        CLI::Option* s = cmd->add_option("--shader", shader,
                                         "Judge your own culling compute shader instead of a built-in algorithm: GLSL "
                                         "(.comp/.glsl), HLSL (.hlsl) or SPIR-V (.spv); docs/CUSTOM_CULLING.md")
                             ->type_name("FILE");
        optLayout = cmd->add_option("--layout", layout,
                                    "Custom shader: how it writes its lists: fixed:N, compact[:N] or bitmask "
                                    "(default: the shader's first line, else fixed:64)")
                        ->type_name("LAYOUT")
                        ->needs(s);
        optLists = cmd->add_option("--lists", lists,
                                   "Custom shader: which list a pixel loops over: tile, halfz, froxel:N[:log|linear] or cells:N[:log|linear] "
                                   "(default: the shader's first line, else tile)")
                       ->type_name("RULE")
                       ->needs(s);
        optEntry = cmd->add_option("--entry", entry, "Custom shader: entry point of HLSL or SPIR-V (default: main)")
                       ->type_name("NAME")
                       ->needs(s);
        cmd->add_flag("--no-validation", noValidation,
                      "Custom shader: run it without the Khronos validation layer (on by default: it is user code)")
            ->needs(s);
        cmd->add_option("--timeout-ms", timeoutMs,
                        "Custom shader: a dispatch still running after this long is reported as a hang (default 10000)")
            ->type_name("MS")
            ->check(CLI::Range(1.0, 3600000.0))
            ->needs(s);
        addDepth(cmd);
    }
    void addDepth(CLI::App* cmd) {
        cmd->add_option("--depth", depthFile,
                        "Judge against this depth buffer instead of the pre-pass: raw float32 window depth (width x "
                        "height, top row first) or a 16-bit PNG, in the scene camera's depth convention")
            ->type_name("FILE");
    }

    lc::CustomShaderOptions shaderOptions(const std::string& device) const {
        lc::CustomShaderOptions o = lc::shaderOptionsFromFile(shader, layout, lists, entry);
        o.device = device;
        o.validation = !noValidation;
        o.timeoutMs = timeoutMs;
        return o;
    }
};

// The lines `run --shader` and `check` add to the summary.
inline void printCustomReport(const lc::RunOutput& run, const lc::Scene& scene, const lc::Projection& proj) {
    if (!run.custom) return;
    const lc::CustomCullReport& c = *run.custom;
    std::cout << "custom: " << c.source << ", layout " << c.layout << ", lists " << c.lists;
    if (c.passMs >= 0) std::cout << ", pass " << c.passMs << " ms on " << c.device;
    // The first list of each kind, with its tile (summary.json lists them).
    const auto first = [&](const std::vector<std::uint32_t>& lists) -> std::string {
        if (lists.empty()) return "";
        const std::uint32_t t = run.result.tileOfList(lists.front()), tx = std::max(run.result.grid.tilesX, 1u);
        return " (first: list " + std::to_string(lists.front()) + ", tile " + std::to_string(t % tx) + "," +
               std::to_string(t / tx) + ")";
    };
    std::cout << "\n  overflowed lists " << c.overflowLists << " (" << c.overflowEntries << " entries lost)"
              << first(c.overflowedListIds) << ", invalid indices " << c.invalidIndices << first(c.invalidIndexListIds)
              << ", duplicates " << c.duplicateIndices << first(c.duplicateIndexListIds) << ", validation messages "
              << c.validationMessages.size() << "\n";
    if (c.builtinAlgorithm.rfind("none", 0) == 0)
        std::cout << "  against built-in: " << c.builtinAlgorithm << "\n"; // "none (why)": nothing to count
    else
        std::cout << "  against built-in " << c.builtinAlgorithm << " (cpu): " << c.listsDifferingFromBuiltin
                  << (c.listsDifferingFromBuiltin == 1 ? " list differs, " : " lists differ, ")
                  << run.result.entries() << (run.result.entries() == 1 ? " entry vs " : " entries vs ")
                  << c.builtinEntries << "\n";
    for (const std::string& w : c.warnings) std::cout << "  warning: " << w << "\n";
    if (!c.headerLayout.empty() &&
        (c.overflowLists || c.invalidIndices || c.duplicateIndices || run.truth.metrics.falseNegatives))
        std::cout << "  note: the shader's settings line says --layout " << c.headerLayout << "; --layout " << c.layout
                  << " overrides it: read in another layout, counts and indices come from the wrong words\n";
    for (std::size_t i = 0; i < c.validationMessages.size() && i < 5; ++i)
        std::cout << "  validation: " << lc::validationGist(c.validationMessages[i]).substr(0, 400) << "\n";
    // The culling test's misses first: a full list is a limit, and its many
    // misses must not hide the shader's real flaw.
    const auto missed = lc::locateFalseNegatives(run, proj);
    for (lc::MissCause cause : {lc::MissCause::CullingTest, lc::MissCause::ListFull, lc::MissCause::InvalidIndex}) {
        std::size_t shown = 0, total = 0;
        for (const auto& m : missed) {
            if (m.cause != cause) continue;
            if (total++ >= 10) continue;
            ++shown;
            std::cout << "  MISSING light " << m.light
                      << (m.light < scene.lights.size() ? " '" + scene.lights[m.light].name + "'" : std::string())
                      << " in tile " << m.tile % run.result.grid.tilesX << "," << m.tile / run.result.grid.tilesX
                      << " (list " << m.list << "): " << m.pixels << (m.pixels == 1 ? " pixel needs it; cause: " : " pixels need it; cause: ") << lc::toString(cause)
                      << "\n";
        }
        if (total > shown)
            std::cout << "  ... " << total - shown << " more missed by " << lc::toString(cause)
                      << " (summary.json custom.missed)\n";
    }
}

} // namespace lcli
