#pragma once
// What the studio says about its runs: the status bar's permanent labels
// (backend and device, depth and cull times, false negatives, efficiency,
// list lengths, the glTF cut-off) and the message log's line per finished or
// failed run (misses by cause under engine limits, a custom shader's report,
// the image error once shaded). The labels follow the document: a stale run's
// figures say so, and a failed run leaves the last good one on screen marked
// as such.

#include <QObject>
#include <QString>

#include <memory>

class QLabel;
class QStatusBar;

namespace lc {
struct RunOutput;
}

namespace lcui {

class Document;
class MessageLog;

class RunStatus : public QObject {
    Q_OBJECT
public:
    RunStatus(Document* doc, MessageLog* log, QStatusBar* bar, QObject* parent);

    // A run finished and is shown (the document took it): its log lines.
    void finished(quint64 generation, const lc::RunOutput& out);
    void failed(quint64 generation, const QString& message);
    // The worker opened a backend (before any run of it is shown).
    void backendReady(const QString& name, const QString& device);
    // The custom shader's file, saved again, was refused (`why`; empty: it
    // is in use again): the run shown is of its earlier version.
    void setShaderRefused(const QString& file, const QString& why);

private:
    void update();
    void updateCutoff(); // the glTF cut-off label: the scene, not the run
    void updateFigures(const lc::RunOutput& run);
    void logCustom(const lc::RunOutput& out);
    void logLimits(quint64 generation, const lc::RunOutput& out);

    Document* doc_;
    MessageLog* log_;
    QStatusBar* bar_;
    QLabel* backend_;
    QLabel* times_;
    QLabel* fn_;
    QLabel* efficiency_;
    QLabel* lists_;
    QLabel* cutoff_;
    QString lastBackendName_, lastDeviceName_;
    // The newest run that failed (0: none): while it is newer than the run
    // shown, the status bar says the figures are an older run's.
    quint64 failedGeneration_ = 0;
    QString refusedFile_, refusedWhy_;
};

} // namespace lcui
