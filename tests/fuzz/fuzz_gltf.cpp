// libFuzzer target: lc::loadGltfScene on arbitrary bytes, written to a
// temporary .glb (bytes starting "glTF") or .gltf file. Any input must load
// into a scene that validates or throw lc::InputError; a crash, a sanitizer
// report, a hang, an allocation past the RSS limit or any other exception is
// a bug. So is a scene the reader returns that fails Scene::validate(): the
// reader's contract is a valid scene or an error, and validate() throws
// InputError for a bad mesh, which must not pass for "bad input" here.
// Loaded scenes are also written back as GLB (the writer must accept
// whatever the reader produced), and the depth pre-pass's host side (its
// closed solids) runs on every mesh.
#include "culling/core/errors.hpp"
#include "culling/scene/gltf_io.hpp"
#include "fuzz_solids.hpp"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

std::string scratchPath(const char* ext) {
    const char* dir = std::getenv("TMPDIR");
    return std::string(dir && *dir ? dir : "/tmp") + "/lightcull-fuzz-" + std::to_string(getpid()) + ext;
}

[[noreturn]] void finding(const char* what, const char* detail) {
    std::fprintf(stderr, "fuzz_gltf: %s: %s\n", what, detail);
    std::abort();
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const bool binary = size >= 4 && data[0] == 'g' && data[1] == 'l' && data[2] == 'T' && data[3] == 'F';
    const std::string path = scratchPath(binary ? ".glb" : ".gltf");
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    if (size && std::fwrite(data, 1, size, f) != size) std::abort();
    std::fclose(f);
    lc::Scene scene;
    try {
        scene = lc::loadGltfScene(path);
    } catch (const lc::InputError&) {
        std::remove(path.c_str()); // bad input: the typed error is the expected outcome
        return 0;
    }
    std::remove(path.c_str());
    // From here on nothing may fail: the reader said the scene is good.
    try {
        scene.validate();
    } catch (const std::exception& e) {
        finding("the reader returned a scene that fails validate()", e.what());
    }
    for (const lc::Mesh& m : scene.meshes) fuzzClosedSolids(m);
    try {
        const std::string glb = lc::serializeGltf(scene, true);
        if (glb.size() < 12) finding("the writer", "wrote fewer than 12 bytes");
    } catch (const std::exception& e) {
        finding("the writer refused a scene the reader returned", e.what());
    }
    return 0;
}
