#pragma once
// The SPIR-V of every shader in shaders/, compiled at build time (see
// shaders/CMakeLists.txt) and embedded as 32-bit words.
#include <cstddef>
#include <cstdint>

namespace lc::spirv {

struct Code {
    const std::uint32_t* words;
    std::size_t wordCount;
    std::size_t bytes() const { return wordCount * sizeof(std::uint32_t); }
};

Code depthVert();   // depth pre-pass vertex shader (no fragment shader)
Code proxySetupComp();  // raster: each proxy triangle's corners and trim, once
Code proxyRasterVert(); // raster: the corners proxy_setup.comp worked out
Code proxyRasterFrag(); // raster: a covered tile's light bit
Code tileBounds();  // per-tile depth bounds, halfz split, cell / slice masks
Code tileBoundsWide();  // the same, depth read 2 or 8 pixels a load (needs shaderInt64)
Code lightBins();  // per tile column / row bitmask of the lights not outside its side planes
Code lightBinsShuffle(); // the same, several invocations a mask word (needs subgroup shuffles)
Code cullLists();   // per-list light tests: count pass and write pass
Code cullListsIndex16(); // the same, writing 16-bit light indices (needs storageBuffer16BitAccess)
Code prefixSum();   // exclusive scan of the list counts into offsets
Code zbin();        // zbin: the depth bins of the depth-sorted lights
Code finePrune();   // fptl: prune the coarse lists against the tile's pixels, then pack them
Code shade();       // Lambert shading pass, one invocation per four pixels of a row

} // namespace lc::spirv
