#include "work/progress_task.hpp"

#include "work/cull_worker.hpp"
#include "widgets/status_progress.hpp"

#include "culling/core/errors.hpp"

#include <QEventLoop>
#include <QThread>
#include <QTimer>

#include <atomic>
#include <future>
#include <memory>

namespace lcui {

namespace {

struct Shared {
    std::shared_ptr<lc::CancelToken> cancel = std::make_shared<lc::CancelToken>();
    std::atomic<double> fraction{-1.0};
    lc::Progress progress = [this](double f) { fraction = f; };
};

// Shows the status row, waits (processing events) until `done` is ready and
// rethrows what the work threw. `shared` outlives the wait: a job the worker
// still holds after a cancel keeps its own reference. With `thread` given, its
// end stops the wait at once; otherwise the 50 ms poll sees it.
void waitModal(StatusProgress* status, const QString& label, const std::shared_ptr<Shared>& shared,
               std::future<void> done, int showAfterMs, const std::function<QString()>& liveLabel,
               QThread* thread = nullptr) {
    const QString key = "load";
    const std::shared_ptr<lc::CancelToken> cancel = shared->cancel;
    status->begin(key, label, [cancel] { cancel->cancelled = true; }, showAfterMs);
    status->blockInput(true);
    QEventLoop loop;
    // Connected before `done` is checked: an end after the check is queued here.
    if (thread) QObject::connect(thread, &QThread::finished, &loop, &QEventLoop::quit);
    QTimer poll;
    QObject::connect(&poll, &QTimer::timeout, [&] {
        status->setProgress(key, shared->fraction.load(), liveLabel ? liveLabel() : QString());
        if (done.wait_for(std::chrono::seconds(0)) == std::future_status::ready) loop.quit();
    });
    poll.start(50);
    if (done.wait_for(std::chrono::seconds(0)) != std::future_status::ready) loop.exec();
    poll.stop();
    status->blockInput(false);
    status->end(key);
    done.get(); // rethrows the work's exception (std::future_error if a job was dropped unrun)
    if (cancel->cancelled) throw lc::Cancelled();
}

} // namespace

void runWithProgress(StatusProgress* status, const QString& label, const ProgressWork& work, int showAfterMs,
                     const std::function<QString()>& liveLabel) {
    auto shared = std::make_shared<Shared>();
    std::promise<void> finished;
    std::future<void> done = finished.get_future();
    // `work` and the promise live on this frame, which waits for the thread.
    QThread* thread = QThread::create([&] {
        try {
            work(*shared->cancel, shared->progress);
            finished.set_value();
        } catch (...) {
            finished.set_exception(std::current_exception());
        }
    });
    thread->start();
    std::exception_ptr error;
    try {
        waitModal(status, label, shared, std::move(done), showAfterMs, liveLabel, thread);
    } catch (...) {
        error = std::current_exception();
    }
    thread->wait();
    delete thread;
    if (error) std::rethrow_exception(error);
}

void runJobWithProgress(StatusProgress* status, CullService* service, const QString& label, ProgressJob job,
                        const std::function<QString()>& liveLabel) {
    auto shared = std::make_shared<Shared>();
    auto finished = std::make_shared<std::promise<void>>();
    std::future<void> done = finished->get_future();
    service->runJob(
        [shared, finished, job = std::move(job)](CullJobContext& context) {
            try {
                job(context, *shared->cancel, shared->progress);
                finished->set_value();
            } catch (...) {
                finished->set_exception(std::current_exception());
            }
        },
        shared->cancel);
    waitModal(status, label, shared, std::move(done), 0, liveLabel);
}

} // namespace lcui
