#pragma once
// Internal to custom culling: shared by custom_cull.cpp and vk/custom_pass.cpp.
#include "culling/custom/custom_cull.hpp"

namespace lc::detail {

// The CPU reference of the built-in algorithm with the list rule of `lists`:
// the grid, tile depth bounds, halfz splits and froxel range a custom result
// shares, and the reference lists it is compared with.
CullResult ruleSkeleton(const DepthImage& depth, const Projection& proj, const TileGrid& grid, const ViewLights& lights,
                        const ListSpec& lists);
// The whole file, bytes as they are; InputError naming it when it cannot be opened.
std::string readWholeFile(const std::string& path);
// `text` without an editor's leading UTF-8 byte order mark (glslang takes it
// for a token; it would hide a first line's "// lightcull:" settings).
inline std::string withoutByteOrderMark(std::string text) {
    if (text.rfind("\xEF\xBB\xBF", 0) == 0) text.erase(0, 3);
    return text;
}
// Fills report.builtin*: how the custom lists differ from the built-in ones.
void compareWithBuiltin(const CullResult& custom, const CullResult& builtin, CustomCullReport& report);

} // namespace lc::detail
