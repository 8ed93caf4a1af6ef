#include "progress_task.hpp"

#include "culling/errors.hpp"

#include <QEventLoop>
#include <QProgressDialog>
#include <QThread>
#include <QTimer>

#include <atomic>

namespace lcui {

void runWithProgress(QWidget* parent, const QString& label,
                     const std::function<void(const lc::CancelToken&, const lc::Progress&)>& work,
                     int showAfterMs) {
    lc::CancelToken cancel;
    std::atomic<double> fraction{0.0};
    std::exception_ptr error;
    const lc::Progress progress = [&fraction](double f) { fraction = f; };

    QProgressDialog dialog(label, QObject::tr("Cancel"), 0, 1000, parent);
    dialog.setWindowModality(Qt::WindowModal);
    dialog.setMinimumDuration(showAfterMs);
    dialog.setAutoClose(false);
    dialog.setAutoReset(false);
    dialog.setValue(0);
    QObject::connect(&dialog, &QProgressDialog::canceled, [&cancel] { cancel.cancelled = true; });

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
        if (dialog.wasCanceled()) cancel.cancelled = true; // also when cancel() is called directly
        else dialog.setValue(int(fraction.load() * 1000));
    });
    poll.start(50);
    thread->start();
    loop.exec(); // "finished" is queued to this thread, so it cannot be missed
    thread->wait();
    delete thread;
    poll.stop();
    if (dialog.wasCanceled()) cancel.cancelled = true;
    dialog.reset();
    if (error) std::rethrow_exception(error);
    if (cancel.cancelled) throw lc::Cancelled();
}

} // namespace lcui
