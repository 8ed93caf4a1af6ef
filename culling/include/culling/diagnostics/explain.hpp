#pragma once
// "Why is this light in this list, and why is that one missing?" For one list
// (a tile, or one of its cells or froxels) and one light: the tests the
// algorithm's CPU reference runs, each with its numbers and verdict, and from
// ground truth how many of the list's pixels need the light or, for a false
// positive, how far the nearest of them is from the light's volume. Shared by
// `lightcull explain` and the studio's Explain panel.

#include "culling/core/pipeline.hpp"
#include "culling/math/projection.hpp"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace lc {

struct ExplainStep {
    std::string test;    // "side plane left", "depth min (near plane of the chunk)", "cell mask", ...
    std::string numbers; // the values compared, e.g. "signed distance -0.412 >= -r = -1.500"
    bool passed = false;
};

struct Explanation {
    std::uint32_t tile = 0, list = 0, light = 0;
    std::uint32_t tileX = 0, tileY = 0; // the tile's column and row (0,0 top-left)
    int sub = -1;              // halfz near 0 / far 1, froxel slice, cell: the sub-list of the tile; -1: none
    std::string algorithm;     // of the result ("custom ..." for a custom shader's)
    glm::dvec3 sphereCenter{0.0}; // the culling sphere the tests use (view space)
    double sphereRadius = 0;
    double chunkDepthMin = 0, chunkDepthMax = 0; // the view-depth range of the tested chunk
    // The tested chunk (view space, FrustumChunk's corner order) and the
    // plane of its six (FrustumChunk's order: left, right, top, bottom, near,
    // far) that decided: the one that rejected the light by the widest margin,
    // or, when all six keep it, the one that came closest to rejecting it
    // (smallest signed distance + r). The studio draws both in 3D.
    bool hasChunk = false;
    std::array<glm::dvec3, 8> chunkCorners{};
    int decisivePlane = -1;
    double decisiveMargin = 0; // signed distance + r of that plane (< 0: rejected)
    std::vector<ExplainStep> steps;
    bool testsPass = false;    // the reference's tests keep the light in this list
    bool listed = false;       // the run's list holds it
    std::uint32_t listPixels = 0, pixelsNeeding = 0;
    // When no pixel of the list needs it: how far the nearest one is outside
    // the light's volume (range sphere; 0 when inside the sphere but outside
    // a spot's cone) and where that pixel is (view space, pixel coordinates).
    double nearestDistance = -1;
    glm::dvec3 nearestPosition{0.0};
    std::uint32_t nearestX = 0, nearestY = 0;
    // When pixels need it: the needing pixel nearest the light's centre (view
    // space), where a miss would show first.
    bool hasNeededPixel = false;
    glm::dvec3 neededPosition{0.0};
    std::string verdict;       // one line: needed / false positive (why) / MISSING / not listed, rightly
    // Listed though the reference's tests reject it: why the run's culling
    // kept it (a GPU's widened comparisons, a rasteriser's coverage, a
    // custom shader's own test). Empty otherwise.
    std::string listedAnyway;
    // The whole explanation, one step a line, as the CLI prints it.
    std::string text(const std::string& lightName = {}) const;
};

// Explains light `light` in list `list` of run.result. Needs run.depth and
// run.lights; throws SettingsError for an index out of range.
Explanation explainLight(const RunOutput& run, const Projection& proj, std::uint32_t list, std::uint32_t light);

// The four corners (view space, in order around it) of plane `plane` (0..5,
// FrustumChunk's plane order) of a chunk with corners `c`.
std::array<glm::dvec3, 4> chunkFace(const std::array<glm::dvec3, 8>& c, int plane);
// The names explain's steps give the six planes.
const char* chunkPlaneName(int plane);

} // namespace lc
