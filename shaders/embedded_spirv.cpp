#include "embedded_spirv.hpp"

#include "cull_lists_comp.spv.h"
#include "cull_lists_index16_comp.spv.h"
#include "depth_vert.spv.h"
#include "fine_prune_comp.spv.h"
#include "light_bins_shuffle_comp.spv.h"
#include "light_bins_comp.spv.h"
#include "prefix_sum_comp.spv.h"
#include "proxy_raster_frag.spv.h"
#include "proxy_raster_vert.spv.h"
#include "proxy_setup_comp.spv.h"
#include "shade_comp.spv.h"
#include "tile_bounds_comp.spv.h"
#include "tile_bounds_wide_comp.spv.h"
#include "zbin_comp.spv.h"

namespace lc::spirv {
#define LC_SPV(fn, arr) \
    Code fn() { return {arr, sizeof(arr) / sizeof(arr[0])}; }
LC_SPV(depthVert, lc_spv_depth_vert)
LC_SPV(tileBounds, lc_spv_tile_bounds_comp)
LC_SPV(tileBoundsWide, lc_spv_tile_bounds_wide_comp)
LC_SPV(lightBins, lc_spv_light_bins_comp)
LC_SPV(lightBinsShuffle, lc_spv_light_bins_shuffle_comp)
LC_SPV(cullLists, lc_spv_cull_lists_comp)
LC_SPV(cullListsIndex16, lc_spv_cull_lists_index16_comp)
LC_SPV(prefixSum, lc_spv_prefix_sum_comp)
LC_SPV(finePrune, lc_spv_fine_prune_comp)
LC_SPV(zbin, lc_spv_zbin_comp)
LC_SPV(shade, lc_spv_shade_comp)
LC_SPV(proxySetupComp, lc_spv_proxy_setup_comp)
LC_SPV(proxyRasterVert, lc_spv_proxy_raster_vert)
LC_SPV(proxyRasterFrag, lc_spv_proxy_raster_frag)
#undef LC_SPV
} // namespace lc::spirv
