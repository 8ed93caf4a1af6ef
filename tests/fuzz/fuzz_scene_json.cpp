// libFuzzer target: the scene JSON reader (lc::parseScene) on arbitrary bytes.
// Any input must either parse into a scene that validates or throw lc::Error;
// a crash, a sanitizer report or any other exception is a bug.
//
// The scene "lives" in a folder that does not exist, so relative mesh paths in
// the input fail to load (a clear InputError) instead of reading the disk.
#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const lc::Scene scene = lc::parseScene(text, "/nonexistent-lightcull-fuzz/scene.json");
        // What parses must survive the rest of the input path: validation and
        // a serialise/parse round trip.
        try {
            scene.validate();
        } catch (const lc::Error&) {
        }
        const std::string again = lc::serializeScene(scene);
        (void)lc::parseScene(again, "/nonexistent-lightcull-fuzz/scene.json");
    } catch (const lc::Error&) {
        // Bad input: the typed error is the expected outcome.
    }
    return 0;
}
