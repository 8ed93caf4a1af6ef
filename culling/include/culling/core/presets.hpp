#pragma once
// Engine presets (docs/ENGINES.md): the culling settings and limits of a
// shipped engine's light culling, modelled with this tool's algorithms. Every
// number comes from the engine's public source, cited in docs/ENGINES.md; a
// preset says what its model leaves out.

#include "culling/core/params.hpp"
#include "culling/scene/scene.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace lc {

struct EnginePreset {
    std::string name;   // "urp", "hdrp-fptl", ... (--preset NAME)
    std::string engine; // "Unity URP Forward+ (desktop)"
    // Parameter -> value, set in this order (the parameter table's names).
    std::vector<std::pair<std::string, std::string>> params;
    // Settings an engine derives from the screen and the light count (URP's
    // tile width from its word budget, Filament's froxel size from its
    // buffer, Unreal's light pool from its grid): applied after `params`.
    std::function<void(CullSettings&, Camera&, std::size_t lightCount)> derive;
    // How the derived settings are worked out, in one line (docs, --help).
    std::string derivedRule;
    // What the model leaves out, in one line.
    std::string leftOut;
    // How far the engine lets each limit be raised, for the fixes the report
    // suggests: the parameter, the most the engine allows (0: no bound; the
    // preset's own value: a constant), and the engine's name for it.
    struct Room {
        std::string param;
        std::uint32_t most = 0;
        std::string setting;
    };
    std::vector<Room> room;
    // The room for `param`, or null when the preset does not name one.
    const Room* roomFor(const std::string& param) const;
};

// Every preset, in docs/ENGINES.md's order.
const std::vector<EnginePreset>& enginePresets();
// Throws SettingsError("preset", ...) naming the known presets.
const EnginePreset& enginePreset(const std::string& name);
// Sets `settings` and the camera's tile size as the preset says for a scene
// of `lightCount` lights seen through `camera` (its resolution as it is).
// `overrides` (parameter, value) are set over the preset's own before its
// settings are derived (a light limit raised re-derives URP's tile width from
// it, as the engine would) and again after (so that they win).
void applyPreset(const EnginePreset& preset, CullSettings& settings, Camera& camera, std::size_t lightCount,
                 const std::vector<std::pair<std::string, std::string>>& overrides = {});

// The preset whose settings for this camera and light count are exactly
// `settings` and the camera's tile size (every culling parameter equal), or
// null: what the studio's preset combo shows and summary.json's "preset".
const EnginePreset* presetMatching(const CullSettings& settings, const Camera& camera, std::size_t lightCount);

} // namespace lc
