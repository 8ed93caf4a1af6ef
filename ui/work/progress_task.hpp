#pragma once
// Modal work: loading a 400k-triangle mesh or a scene, generating tens of
// thousands of lights, a hunt. The window waits for it while the status bar
// (StatusProgress) shows how far it got and offers Cancel; the UI keeps
// processing events (views repaint) but takes no input besides Cancel.
//
// Work that needs a backend runs as a job of the culling worker (one device,
// culling requests served between its steps); work that needs none (reading
// files, generating lights) on a thread of its own, so that a long load
// never holds up a culling run.

#include "culling/core/depth.hpp"
#include "culling/scene/scene_io.hpp"

#include <QString>

#include <exception>
#include <functional>
#include <optional>


namespace lcui {

class CullJobContext;
class CullService;
class StatusProgress;

using ProgressWork = std::function<void(const lc::CancelToken&, const lc::Progress&)>;
using ProgressJob = std::function<void(CullJobContext&, const lc::CancelToken&, const lc::Progress&)>;

// Runs `work` on a new thread and waits (processing events) until it returns.
// Its status row ("load": statusCancel_load, ...) shows at once by default:
// the window ignores clicks meanwhile, and the row says why.
// Cancel sets the token; work that does not check it still runs to its end,
// and its result is then discarded. Rethrows the work's exception; throws
// lc::Cancelled when cancelled. `liveLabel`, when set, is asked for the row's
// label as often as the progress is shown (it must be safe to call while the
// work runs).
void runWithProgress(StatusProgress* status, const QString& label, const ProgressWork& work, int showAfterMs = 0,
                     const std::function<QString()>& liveLabel = {});

// The same wait for `job` run on the culling worker's thread and backends
// (CullService::runJob). Its token is also set when the worker shuts down.
void runJobWithProgress(StatusProgress* status, CullService* service, const QString& label, ProgressJob job,
                        const std::function<QString()>& liveLabel = {});

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
