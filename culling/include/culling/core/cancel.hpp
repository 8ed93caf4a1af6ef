#pragma once
// Cooperative cancellation of long work (the depth rasteriser, ground truth,
// reports, the hunt): the caller sets the flag, the work checks it between
// chunks and stops with lc::Cancelled.

#include "culling/core/errors.hpp"

#include <atomic>

namespace lc {

struct CancelToken {
    std::atomic<bool> cancelled{false};
    void throwIfCancelled() const {
        if (cancelled.load(std::memory_order_relaxed)) throw Cancelled();
    }
};

} // namespace lc
