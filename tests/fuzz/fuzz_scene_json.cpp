// libFuzzer target: the scene JSON reader (lc::parseScene) on arbitrary bytes.
// Any input must either parse into a scene that validates or throw lc::Error;
// a crash, a sanitizer report or any other exception is a bug. So is a scene
// the reader returns that fails Scene::validate() (the reader checks the
// camera, every light and every mesh as it reads them: what it returns is a
// scene the rest of the program may use), and one that does not survive a
// serialise/parse round trip.
//
// The scene "lives" in a folder that does not exist, so relative mesh paths in
// the input fail to load (a clear InputError) instead of reading the disk.
#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

[[noreturn]] void finding(const char* what, const char* detail) {
    std::fprintf(stderr, "fuzz_scene_json: %s: %s\n", what, detail);
    std::abort();
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    const char* path = "/nonexistent-lightcull-fuzz/scene.json";
    lc::Scene scene;
    try {
        scene = lc::parseScene(text, path);
    } catch (const lc::Error&) {
        return 0; // bad input: the typed error is the expected outcome
    }
    // What parses must survive the rest of the input path: validation and
    // a serialise/parse round trip.
    try {
        scene.validate();
    } catch (const std::exception& e) {
        finding("the reader returned a scene that fails validate()", e.what());
    }
    try {
        const std::string again = lc::serializeScene(scene);
        (void)lc::parseScene(again, path);
    } catch (const std::exception& e) {
        finding("a parsed scene does not survive serialise and parse", e.what());
    }
    return 0;
}
