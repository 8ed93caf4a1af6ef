#pragma once
// Where a CLI command's scene comes from: --scene FILE (scene JSON, .gltf or
// .glb) or --builtin NAME, plus the glTF reading options. One definition
// shared by run, bench, report and convert.
#include "culling/core/errors.hpp"
#include "culling/scene/gltf_io.hpp"
#include "culling/scene/scene_io.hpp"

#include <CLI/CLI.hpp>

#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>

namespace lcli {

struct SceneSource {
    std::string sceneFile, builtin;
    lc::GltfReadOptions gltf;

    // Adds --scene and --builtin (or, with `positional`, the first positional
    // argument IN), --camera and --min-intensity.
    void addTo(CLI::App* cmd, bool positional = false) {
        positional_ = positional;
        CLI::Option* optScene =
            cmd->add_option(positional ? "in" : "--scene", sceneFile,
                            "Scene to load: scene JSON, glTF 2.0 (.gltf) or binary glTF (.glb)")
                ->type_name(positional ? "IN" : "FILE");
        if (positional) {
            optScene->required();
        } else {
            CLI::Option* optBuiltin =
                cmd->add_option("--builtin", builtin, "Built-in scene to use (see `lightcull scenes`)")->type_name("NAME");
            optScene->excludes(optBuiltin);
        }
        optCamera_ = cmd->add_option("--camera", gltf.camera,
                        "glTF: the culling camera, by camera or node name or by index into the file's cameras "
                        "(default: the first camera in the scene's node order; none: one framing the scene)")
            ->type_name("NAME|INDEX")
            ->needs(optScene);
        optMinIntensity_ = cmd->add_option("--min-intensity", gltf.minIntensity,
                        "glTF: I_min in lux that sets the culling radius of a light without `range`, "
                        "r = sqrt(intensity x max colour / I_min) (default: 0.01)")
            ->type_name("LUX")
            ->needs(optScene);
    }

    bool given() const { return !sceneFile.empty() || !builtin.empty(); }

    // Loads it; glTF warnings go to stderr, one line each.
    lc::Scene load() const {
        if (sceneFile.empty()) return lc::makeBuiltinScene(builtin);
        checkSceneExtension(positional_ ? "IN" : "--scene", sceneFile);
        // A scene JSON holds its camera and each light's I_min: a glTF
        // option given with one would be ignored without a word.
        if (!lc::isGltfPath(sceneFile))
            for (CLI::Option* o : {optCamera_, optMinIntensity_})
                if (o && o->count())
                    throw lc::SettingsError(o->get_name(), "applies to glTF scenes; " + sceneFile +
                                                                         " is scene JSON, which holds its own");
        lc::GltfReadReport report;
        const auto t0 = std::chrono::steady_clock::now();
        lc::Scene s = lc::loadSceneAny(sceneFile, gltf, &report);
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        for (const std::string& w : report.warnings) std::cerr << "lightcull: warning: " << w << "\n";
        // An explicit cut-off that sizes no light changes nothing: say so
        // (summary.json records gltf_cutoff_lights 0 beside it).
        if (lc::isGltfPath(sceneFile) && optMinIntensity_ && optMinIntensity_->count() &&
            lc::gltfCutoffLights(s).empty())
            std::cerr << "lightcull: warning: --min-intensity applies to no light: every light of " << sceneFile
                      << " has a range\n";
        if (lc::isGltfPath(sceneFile))
            std::cerr << "lightcull: " << sceneFile << ": " << s.triangleCount()
                      << (s.triangleCount() == 1 ? " triangle, " : " triangles, ") << s.lights.size()
                      << (s.lights.size() == 1 ? " light, camera " : " lights, camera ") << report.camera << "; loaded in " << std::lround(ms) << " ms\n";
        return s;
    }

    // Scene files are told apart by extension (docs/CLI.md): .json, .gltf or
    // .glb. A mesh given as a scene, or any other name, is a clear error
    // instead of a JSON parse error or a scene JSON written under .obj.
    static void checkSceneExtension(const std::string& what, const std::string& path) {
        std::string ext = std::filesystem::path(path).extension().string();
        for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
        if (ext == ".json" || ext == ".gltf" || ext == ".glb") return;
        if (what != "OUT" && (ext == ".obj" || ext == ".ply" || ext == ".off" || ext == ".stl"))
            throw lc::SettingsError(what, path + " is a mesh, not a scene: name it in a scene JSON's meshes "
                                                 "(docs/FORMATS.md) or import it in the studio");
        throw lc::SettingsError(what, path + ": a scene is .json (scene JSON), .gltf or .glb (glTF 2.0)");
    }

private:
    bool positional_ = false;
    CLI::Option* optCamera_ = nullptr;
    CLI::Option* optMinIntensity_ = nullptr;
};

} // namespace lcli
