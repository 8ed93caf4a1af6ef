// libFuzzer target: lc::loadMesh on arbitrary bytes written to a temporary
// file with the extension LC_FUZZ_EXT ("obj", "ply" and "off" exercise the
// project's own readers; "stl" goes through OpenMesh's). Any input must
// load into a mesh that validates or throw lc::InputError; a crash, a
// sanitizer report or any other exception is a bug. The depth pre-pass's
// host side (its closed solids) runs on every mesh loaded.
#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"
#include "fuzz_solids.hpp"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#ifndef LC_FUZZ_EXT
#error "LC_FUZZ_EXT (mesh file extension) must be defined"
#endif

namespace {

// One file per fuzzing process, rewritten for every input.
const std::string& scratchPath() {
    static const std::string path = [] {
        const char* dir = std::getenv("TMPDIR");
        return std::string(dir && *dir ? dir : "/tmp") + "/lightcull-fuzz-" + std::to_string(getpid()) + "." +
               LC_FUZZ_EXT;
    }();
    return path;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string& path = scratchPath();
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    if (size && std::fwrite(data, 1, size, f) != size) std::abort();
    std::fclose(f);
    try {
        lc::MeshLoadReport report;
        const lc::Mesh mesh = lc::loadMesh(path, &report);
        // A loaded mesh is valid by contract: finite coordinates, indices in range.
        if (!mesh.validate().empty() || mesh.indices.empty()) std::abort();
        fuzzClosedSolids(mesh);
    } catch (const lc::InputError&) {
    }
    std::remove(path.c_str());
    return 0;
}
