#pragma once
// Long operations (loading a 400k-triangle mesh or a scene, generating tens of
// thousands of lights) run on a background thread while the status bar
// (StatusProgress) shows how far they got and offers Cancel. The UI keeps
// processing events (views repaint) but takes no input besides Cancel.

#include "culling/core/depth.hpp"
#include "culling/scene/scene_io.hpp"

#include <QString>

#include <exception>
#include <functional>
#include <optional>


namespace lcui {

class StatusProgress;

// Runs `work` on a new thread and waits (processing events) until it returns.
// Its status row ("load": statusCancel_load, ...) shows at once by default:
// the window ignores clicks meanwhile, and the row says why.
// Cancel sets the token; work that does not check it still runs to its end,
// and its result is then discarded. Rethrows the work's exception; throws
// lc::Cancelled when cancelled. `liveLabel`, when set, is asked for the row's
// label as often as the progress is shown (it must be safe to call while the
// work runs).
void runWithProgress(StatusProgress* status, const QString& label,
                     const std::function<void(const lc::CancelToken&, const lc::Progress&)>& work,
                     int showAfterMs = 0, const std::function<QString()>& liveLabel = {});

template <class T>
T runWithProgressResult(StatusProgress* status, const QString& label,
                        const std::function<T(const lc::CancelToken&, const lc::Progress&)>& work,
                        int showAfterMs = 0) {
    std::optional<T> result;
    runWithProgress(
        status, label,
        [&](const lc::CancelToken& c, const lc::Progress& p) { result.emplace(work(c, p)); },
        showAfterMs);
    return std::move(*result);
}

} // namespace lcui
