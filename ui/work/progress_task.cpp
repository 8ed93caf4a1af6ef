#include "work/progress_task.hpp"

#include "widgets/status_progress.hpp"

#include "culling/core/errors.hpp"

#include <QEventLoop>
#include <QThread>
#include <QTimer>

#include <atomic>

namespace lcui {

void runWithProgress(StatusProgress* status, const QString& label,
                     const std::function<void(const lc::CancelToken&, const lc::Progress&)>& work,
                     int showAfterMs, const std::function<QString()>& liveLabel) {
    lc::CancelToken cancel;
    std::atomic<double> fraction{-1.0};
    std::exception_ptr error;
    const lc::Progress progress = [&fraction](double f) { fraction = f; };

    const QString key = "load";
    status->begin(key, label, [&cancel] { cancel.cancelled = true; }, showAfterMs);
    status->blockInput(true);

    QThread* thread = QThread::create([&] {
        try {
            work(cancel, progress);
        } catch (...) {
            error = std::current_exception();
        }
    });
    QEventLoop loop;
    QObject::connect(thread, &QThread::finished, &loop, &QEventLoop::quit);
    QTimer poll;
    QObject::connect(&poll, &QTimer::timeout, [&] {
        status->setProgress(key, fraction.load(), liveLabel ? liveLabel() : QString());
    });
    poll.start(50);
    thread->start();
    loop.exec(); // "finished" is queued to this thread, so it cannot be missed
    thread->wait();
    delete thread;
    poll.stop();
    status->blockInput(false);
    status->end(key);
    if (error) std::rethrow_exception(error);
    if (cancel.cancelled) throw lc::Cancelled();
}

} // namespace lcui
