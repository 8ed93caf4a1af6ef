#pragma once
// The Lambert shading pass and the image error (DESIGN.md, "Ground truth and
// the error metrics"): every geometry pixel is shaded from the lights of its
// list (CullResult::listOfPixel, the rule the ground truth uses) or from every
// light, and the two images are compared.
//
// Per pixel p with view position P and shading normal n (both view space):
//   rgb(p) = sum_i power_i * max(0, n . l_i) / max(|c_i - P|^2, 1e-4),
//   l_i = (c_i - P) / |c_i - P|,
// times, for a light with a shading range r (ViewLights::shadingRanges: a glTF
// `range`, a scene JSON `radius`), KHR_lights_punctual's window
//   max(0, 1 - (|c_i - P|^2 / r^2)^2)^2,
// so that such a light adds nothing beyond its range; a spot light adds only
// inside its cone (a hard cone);
// accumulated in list order (ascending light index) in float. The normal comes
// from the depth buffer: per axis the shorter of the forward and backward
// differences of the neighbours' view positions, facing the camera; without a
// neighbour in x or y, the direction to the camera.

#include "culling/core/backend.hpp"

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace lc {

// The "G-buffer" a shading pass reads, shared by the CPU reference and the
// Vulkan pass so both shade bitwise the same inputs: per pixel (row-major) the
// view position, the shading normal and the list the pixel loops over
// (kNoList for background pixels). Positions and normals are float.
// 1 / range^2 as the shading passes take it (float); 0 for no range. Held
// below float's largest value so that a pixel at the light gets 0 * it = 0.
inline float shadingInvRange2(double range) {
    return range > 0.0 ? float(std::min(1.0 / (range * range), 3.0e38)) : 0.0f;
}

struct ShadeInputs {
    static constexpr std::uint32_t kNoList = 0xffffffffu;
    std::uint32_t width = 0, height = 0;
    std::vector<float> position; // 3 per pixel
    std::vector<float> normal;   // 3 per pixel
    std::vector<std::uint32_t> list;
    // Each geometry pixel's view depth, as Projection::viewDepthFromWindowDepth
    // gives it (0 elsewhere): setShadeLists finds each pixel's cell from it
    // without converting the depth again for every result.
    std::vector<double> viewDepth;
    // Which makeShadeInputs call made position and normal (0: made some other
    // way). A shading pass handed the G-buffer it shaded last time, the same
    // id and the same arrays, skips its upload (a sweep shades each G-buffer
    // many times with different lists).
    std::uint64_t gbufferId = 0;
    // zbin: the per-(tile, bin) lists `list` indexes (zbinPixelLists), which
    // every shading pass uses instead of the (non-null) result it is handed.
    std::shared_ptr<const CullResult> perPixelLists;
};

// Builds the G-buffer of `depth`. With `culled` null every geometry pixel uses
// list 0 of "every light"; a zbin result brings its per-pixel lists along.
// Throws Error when sizes disagree.
ShadeInputs makeShadeInputs(const DepthImage& depth, const Projection& proj, const CullResult* culled);
// Points `in`, made by makeShadeInputs for this depth image and camera, at the
// lists of `culled` (null: every light): only the per-pixel list changes, so a
// sweep over many results of one frame builds the G-buffer once.
void setShadeLists(ShadeInputs& in, const DepthImage& depth, const Projection& proj, const CullResult* culled);

// The CPU reference of the shading pass: RGB, 3 floats per pixel, background 0.
// `culled` null: every light in index order. Throws Error when a list is out of
// range or names a light that does not exist.
std::vector<float> shadeCpu(const ShadeInputs& in, const ViewLights& lights, const CullResult* culled);

// Convenience: makeShadeInputs + shadeCpu.
std::vector<float> shadeLambertCpu(const DepthImage& depth, const Projection& proj, const ViewLights& lights,
                                   const CullResult* culled /* null: all lights */);

// Image error of `culled` against `reference` over the geometry pixels of
// `depth`: RMSE over every channel of every geometry pixel, and the largest
// absolute channel difference.
struct ImageError {
    double rmse = 0, maxAbs = 0;
    std::uint64_t pixels = 0;
};
ImageError compareShadedImages(const DepthImage& depth, const std::vector<float>& culled,
                               const std::vector<float>& reference);

// 8-bit pictures of shaded images (RGB, width x height). `exposure` scales
// linear values before clamping and sRGB encoding; exposureFor() picks one that
// maps the 99th percentile of the reference's geometry pixels to 0.9.
// differencePicture shows |culled - reference| scaled so that `maxAbs` is white.
double exposureFor(const DepthImage& depth, const std::vector<float>& reference);
std::vector<std::uint8_t> shadedPicture(const std::vector<float>& rgb, double exposure);
std::vector<std::uint8_t> differencePicture(const std::vector<float>& culled, const std::vector<float>& reference,
                                            double maxAbs);

} // namespace lc
