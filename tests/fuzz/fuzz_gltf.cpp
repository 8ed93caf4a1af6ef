// libFuzzer target: lc::loadGltfScene on arbitrary bytes, written to a
// temporary .glb (bytes starting "glTF") or .gltf file. Any input must load
// into a scene that validates or throw lc::InputError; a crash, a sanitizer
// report, a hang, an allocation past the RSS limit or any other exception is
// a bug. Loaded scenes are also written back as GLB (the writer must accept
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

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const bool binary = size >= 4 && data[0] == 'g' && data[1] == 'l' && data[2] == 'T' && data[3] == 'F';
    const std::string path = scratchPath(binary ? ".glb" : ".gltf");
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    if (size && std::fwrite(data, 1, size, f) != size) std::abort();
    std::fclose(f);
    try {
        const lc::Scene scene = lc::loadGltfScene(path);
        scene.validate(); // by contract: a loaded scene is valid
        for (const lc::Mesh& m : scene.meshes) fuzzClosedSolids(m);
        const std::string glb = lc::serializeGltf(scene, true);
        if (glb.size() < 12) std::abort();
    } catch (const lc::InputError&) {
    }
    std::remove(path.c_str());
    return 0;
}
