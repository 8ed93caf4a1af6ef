#pragma once
// `lightcull hunt`: search random small trials for a configuration where a
// culling misses a light, and write the shrunk repro (docs/CLI.md, "hunt";
// the search itself is culling/diagnostics/hunt.hpp).
#include "scene_source.hpp"

#include "culling/diagnostics/hunt.hpp"

#include <CLI/CLI.hpp>

#include <map>
#include <string>
#include <vector>

namespace lcli {

class HuntCommand {
public:
    // Registers the `hunt` subcommand and its flags on `app`.
    void add(CLI::App& app);
    bool chosen() const { return cmd_ && cmd_->parsed(); }
    // Runs it. Returns the exit code: 0 no counterexample, 3 one found (its
    // repro written into --out), 2 a bad command line (message printed);
    // throws lc::Error for failures while running.
    int run();

private:
    // --path: every frame of the camera path through `scene`.
    int runPath(lc::HuntOptions& options, const lc::Scene& scene, lc::CullBackend& backend);
    CLI::App* cmd_ = nullptr;
    SceneSource source_;
    std::string outDir_, backend_, device_, shader_, layout_, lists_, vary_ = "all", path_, animation_, preset_;
    unsigned long long seed_ = 1, trials_ = 0;
    double budget_ = 0, timeoutMs_ = 10000, fps_ = 30;
    // The random search's own flags, refused with --path.
    std::vector<CLI::Option*> searchOptions_;
    bool overflow_ = false, noValidation_ = false;
    std::map<std::string, std::string> paramValues_;
    std::vector<std::pair<std::string, CLI::Option*>> paramOptions_;
};

} // namespace lcli
