#pragma once
// Long operations (loading a 400k-triangle mesh or a scene, generating tens of
// thousands of lights) run on a background thread while a progress dialog
// shows how far they got and offers Cancel. The UI keeps processing events.

#include "culling/depth.hpp"
#include "culling/scene_io.hpp"

#include <QString>

#include <exception>
#include <functional>
#include <optional>

class QWidget;

namespace lcui {

// Runs `work` on a new thread and waits (processing events) until it returns.
// The dialog appears only when the work takes longer than `showAfterMs`.
// Cancel sets the token; work that does not check it still runs to its end,
// and its result is then discarded. Rethrows the work's exception; throws
// lc::Cancelled when cancelled.
void runWithProgress(QWidget* parent, const QString& label,
                     const std::function<void(const lc::CancelToken&, const lc::Progress&)>& work,
                     int showAfterMs = 300);

template <class T>
T runWithProgressResult(QWidget* parent, const QString& label,
                        const std::function<T(const lc::CancelToken&, const lc::Progress&)>& work,
                        int showAfterMs = 300) {
    std::optional<T> result;
    runWithProgress(
        parent, label,
        [&](const lc::CancelToken& c, const lc::Progress& p) { result.emplace(work(c, p)); },
        showAfterMs);
    return std::move(*result);
}

} // namespace lcui
