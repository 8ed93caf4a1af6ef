// libFuzzer target: lc::loadCameraPath on arbitrary bytes, in two modes chosen
// by how the input starts: bytes starting "glTF" are written as a .glb, a
// first byte 'G' is dropped and the rest written as a .gltf (the glTF camera
// animation reader), anything else is written as a JSON camera path (.json).
// Any input must give a path that keeps the reader's contract or throw
// lc::InputError; a crash, a sanitizer report, a hang, an allocation past the
// RSS limit or any other exception is a bug. The contract: 1..maxFrames
// frames, times finite and non-decreasing, every camera valid, a one-line
// description. maxFrames is kept small so that a long animation is refused
// (or sampled) quickly; the arguments are valid, so a SettingsError is a bug.
#include "culling/core/errors.hpp"
#include "culling/scene/camera_path.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

constexpr std::size_t kMaxFrames = 2000;

std::string scratchPath(const char* ext) {
    const char* dir = std::getenv("TMPDIR");
    return std::string(dir && *dir ? dir : "/tmp") + "/lightcull-fuzz-path-" + std::to_string(getpid()) + ext;
}

[[noreturn]] void finding(const char* what, const std::string& detail) {
    std::fprintf(stderr, "fuzz_camera_path: %s: %s\n", what, detail.c_str());
    std::abort();
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const bool glb = size >= 4 && data[0] == 'g' && data[1] == 'l' && data[2] == 'T' && data[3] == 'F';
    const bool gltf = !glb && size >= 1 && data[0] == 'G';
    const std::string path = scratchPath(glb ? ".glb" : gltf ? ".gltf" : ".json");
    const std::size_t skip = gltf ? 1 : 0;
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    if (size > skip && std::fwrite(data + skip, 1, size - skip, f) != size - skip) std::abort();
    std::fclose(f);

    lc::Camera base;
    base.width = 64;
    base.height = 48;
    lc::CameraPath cp;
    try {
        cp = lc::loadCameraPath(path, base, 30, {}, kMaxFrames);
    } catch (const lc::InputError&) {
        std::remove(path.c_str()); // bad input: the typed error is the expected outcome
        return 0;
    } catch (const std::exception& e) {
        std::remove(path.c_str());
        finding("not an InputError", e.what());
    }
    std::remove(path.c_str());
    if (cp.frames.empty() || cp.frames.size() > kMaxFrames)
        finding("frame count outside 1..maxFrames", std::to_string(cp.frames.size()));
    if (cp.description.empty() || cp.description.find('\n') != std::string::npos)
        finding("the description is not one line", cp.description);
    for (std::size_t i = 0; i < cp.frames.size(); ++i) {
        const lc::CameraPathFrame& fr = cp.frames[i];
        if (!std::isfinite(fr.time)) finding("a frame time is not finite", std::to_string(i));
        if (i > 0 && fr.time < cp.frames[i - 1].time) finding("frame times decrease", std::to_string(i));
        if (std::string e = fr.camera.validate(); !e.empty()) finding("a frame's camera fails validate()", e);
    }
    return 0;
}
