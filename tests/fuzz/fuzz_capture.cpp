// libFuzzer target: a RenderDoc capture description and the bytes a replay
// hands back (culling/capture/capture_frame.hpp). The input is the
// description's JSON, a NUL byte, then the bindings' bytes: for each binding
// the description reads (in captureBindingsNeeded's order), one byte choosing
// its kind and format (images: a byte each of width and height, 1..64), two
// bytes of length and that many bytes. Any input must give a frame that
// keeps the decoder's contract, judged by the one pipeline, or throw
// lc::InputError; a crash, a sanitizer report, a hang, an unbounded
// allocation or any other exception is a bug.
#include "culling/capture/capture_frame.hpp"
#include "culling/core/errors.hpp"
#include "culling/core/pipeline.hpp"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace {

[[noreturn]] void finding(const char* what, const std::string& detail) {
    std::fprintf(stderr, "fuzz_capture: %s: %s\n", what, detail.c_str());
    std::abort();
}

const char* const kFormats[] = {"D32", "R32_FLOAT", "D16", "D24S8", "D32S8", "B8G8R8A8_UNORM"};

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto* end = static_cast<const std::uint8_t*>(std::memchr(data, 0, size));
    if (!end) return 0;
    const std::string text(reinterpret_cast<const char*>(data), std::size_t(end - data));
    std::size_t at = std::size_t(end - data) + 1;
    lc::CaptureDescription d;
    try {
        d = lc::parseCaptureDescription(text, "fuzz.json");
    } catch (const lc::InputError&) {
        return 0;
    } catch (const std::exception& e) {
        finding("parseCaptureDescription threw a non-InputError", e.what());
    }
    std::map<std::string, lc::CaptureBlob> blobs;
    std::uint32_t binding = 0;
    for (const auto& [key, spec] : lc::captureBindingsNeeded(d)) {
        lc::CaptureBlob b;
        b.binding.binding = binding++;
        b.binding.resource = spec;
        const std::uint8_t kind = at < size ? data[at++] : 0;
        b.binding.kind = kind & 1 ? "image" : "buffer";
        if (kind & 1) {
            b.binding.format = kFormats[(kind >> 1) % 6];
            b.binding.componentBytes = b.binding.format == "D16" ? 2 : b.binding.format == "B8G8R8A8_UNORM" ? 1 : 4;
            b.binding.components = 1;
            b.binding.componentType = "Float";
            b.binding.samples = (kind & 0x80) ? 4 : 1;
            b.binding.width = at < size ? 1 + data[at++] % 64 : 1;
            b.binding.height = at < size ? 1 + data[at++] % 64 : 1;
        }
        std::size_t n = 0;
        if (at + 2 <= size) n = std::size_t(data[at]) | std::size_t(data[at + 1]) << 8, at += 2;
        n = std::min(n, size - std::min(size, at));
        b.bytes.assign(reinterpret_cast<const char*>(data + at), n);
        at += n;
        blobs.emplace(key, std::move(b));
    }
    try {
        const lc::CaptureFrame f = lc::decodeCaptureFrame(d, blobs, "fuzz.rdc", 1);
        if (f.depth.depth.size() != std::size_t(f.depth.width) * f.depth.height || f.depth.depth.empty())
            finding("depth size", std::to_string(f.depth.width) + "x" + std::to_string(f.depth.height));
        if (const std::string bad = f.scene.camera.validate(); !bad.empty()) finding("invalid camera", bad);
        for (const lc::Light& l : f.scene.lights)
            if (const std::string bad = l.validate(); !bad.empty()) finding("invalid light", bad);
        for (float v : f.depth.depth)
            if (!(v >= 0.0f && v <= 1.0f)) finding("depth outside 0..1", std::to_string(v));
        lc::CustomCullReport report;
        lc::RunOptions o;
        o.truthOptions.imageError = false;
        (void)lc::checkCaptureFrame(f, o, report);
    } catch (const lc::InputError&) {
    } catch (const std::exception& e) {
        finding("decoding threw a non-InputError", e.what());
    }
    return 0;
}
