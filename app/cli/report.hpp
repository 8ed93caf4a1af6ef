#pragma once
// `lightcull report`: the speed-against-error sweep (culling/diagnostics/report.hpp) of
// one scene, written as report.csv, report.md and pareto.png.
#include "scene_source.hpp"

#include <CLI/CLI.hpp>

#include <map>
#include <string>
#include <vector>

namespace lcli {

class ReportCommand {
public:
    // Registers the `report` subcommand and its flags on `app`.
    void add(CLI::App& app);
    bool chosen() const { return cmd_ && cmd_->parsed(); }
    // Runs it. Returns the exit code (2: bad command line, message printed);
    // throws lc::Error for failures while running.
    int run();

private:
    CLI::App* cmd_ = nullptr;
    SceneSource source_;
    std::string outDir_, device_;
    std::vector<std::string> backends_, shaders_, presets_;
    bool allPresets_ = false;
    long long lights_ = -1;
    unsigned long long seed_ = 1;
    double spotFraction_ = 0.0;
    double timeoutMs_ = 10000; // custom shaders' time limit (CustomShaderOptions)
    int repeat_ = 3, warmup_ = 1;
    CLI::Option* optLights_ = nullptr;
    std::map<std::string, std::string> paramValues_;
    std::vector<std::pair<std::string, CLI::Option*>> paramOptions_;
};

} // namespace lcli
