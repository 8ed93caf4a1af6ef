#pragma once
// The Report dock: the speed-against-error sweep of culling/diagnostics/report.hpp on the
// document's scene, run as a job of the culling worker (its thread and
// backends: one Vulkan device; the worker serves culling requests between the
// sweep's configurations, so Live stays live), plotted with
// VTK charts (total time against efficiency or image error, one series per
// algorithm, the Pareto front as a line).
//
// Before a run the dock says how many configurations the choice queues and,
// from the pace of the last run of this scene, how long they will take; a
// sweep over `confirmAboveSeconds` is asked about first (without a pace, after
// its first configuration has been timed). Each swept parameter can be held
// at one value or a subset (ReportOptions::fixed, tileSizes, cellCounts: the
// CLI's mechanism). While running: configurations done of queued and the time
// left at the measured pace. Cancel keeps the rows that finished, as a
// partial report. A point's tooltip names its configuration; clicking it
// loads that configuration into the document (its tile size into the camera,
// one undo step) and asks for it to be culled (cullRequested), so the views
// show its result.

#include "culling/core/depth.hpp"
#include "culling/diagnostics/report.hpp"

#include <QElapsedTimer>
#include <QWidget>

#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>

#include <vtkChartXY.h>
#include <vtkContextView.h>
#include <vtkSmartPointer.h>

class QComboBox;
class QLabel;
class QMenu;
class QProgressBar;
class QPushButton;
class QSpinBox;
class QToolButton;
class QVTKOpenGLNativeWidget;
class vtkObject;
class vtkPlot;

namespace lcui {

class CullService;
class Document;

class ReportDock : public QWidget {
    Q_OBJECT
public:
    ReportDock(Document* doc, CullService* service, QWidget* parent = nullptr);
    ~ReportDock() override; // cancels a running sweep

    // What start() sweeps. The controls set backends, repeat, fixed (the
    // held parameters), tileSizes and cellCounts; tests may set warmup.
    lc::ReportOptions& options() { return options_; }
    // Starts a sweep of a copy of the document's scene; false while one runs,
    // or when the user declines a long one.
    bool start();
    void cancel();
    bool isRunning() const { return running_; }
    // The last report shown (Report::cancelled: the rows a cancelled sweep
    // finished), or null.
    const lc::Report* report() const { return report_.get(); }
    // Loads row `row` of the report into the document (settings and tile
    // size) and emits cullRequested.
    void loadRow(std::size_t row);

    // Asked before a long sweep (yes: run it). Replaceable, like
    // MainWindow::prompts, so tests answer without a modal loop.
    std::function<bool(QWidget*, const QString& title, const QString& text)> confirm;
    // A sweep estimated to take longer than this is asked about.
    double confirmAboveSeconds = 600;

    // The configurations the controls queue now (every backend that would be
    // swept), and their estimated seconds (nothing without a pace).
    std::size_t queuedConfigurations() const;
    std::optional<double> estimatedSeconds() const;

    // --- for tests --------------------------------------------------------------
    QVTKOpenGLNativeWidget* chartWidget() const { return chartWidget_; }
    QProgressBar* progressBar() const { return progress_; }
    // Where row `row` is drawn in chartWidget(), in widget (logical) pixels;
    // nothing when the row is not plotted.
    std::optional<QPoint> chartPositionOf(std::size_t row) const;
    // The chart's tooltip (what hovering a point shows) and title.
    QString chartTooltip() const;
    bool chartTooltipVisible() const;
    QString chartTitle() const;
    // The text a point of row `row` shows as its tooltip.
    QString tooltipOf(std::size_t row) const;

signals:
    void started();
    // A configuration of the sweep finished (the status bar mirrors the dock's bar).
    void progressed(int done, int total, const QString& label);
    // ok: a whole report was made (false: cancelled, partial or not, or failed).
    void finished(bool ok);
    void configurationLoaded(int row);
    // A loaded configuration wants culling on `backend` (the window runs it).
    void cullRequested(const QString& backend);

private:
    // A held parameter: its menu of values, each checkable.
    struct ParamControl {
        std::string name;
        QToolButton* button = nullptr;
        QMenu* menu = nullptr;
        std::vector<std::string> values;
    };
    // The worker waits here after its first configuration while the dock
    // decides whether to go on (the sweep had no pace to estimate it by).
    struct Gate {
        std::mutex mutex;
        std::condition_variable cv;
        bool open = false;
    };

    void addParamControl(const lc::ParamSpec& p, const std::vector<std::string>& values,
                         const std::vector<std::string>& checked);
    void paramToggled(ParamControl& c, QAction* changed);
    // options_ with the controls' backends, repeat and held parameters.
    lc::ReportOptions optionsFromControls() const;
    std::vector<std::string> sweptBackends() const;
    std::map<std::string, std::size_t> queuedPerBackend() const;
    // queuedPerBackend's last answer and what it depended on.
    mutable std::string queuedKey_;
    mutable std::map<std::string, std::size_t> queued_;
    // What a pace was measured under (scene, size, lights, repeats).
    QString paceKey() const;
    void updateQueueLabel();
    void releaseGate();
    void stopSweep();
    void onProgress(int done, int total, const QString& label);
    // sceneGone: the sweep was of a scene another one replaced (nothing shown).
    void onDone(std::shared_ptr<lc::Report> report, const QString& error, bool cancelled, bool sceneGone);
    void onRunOutput();
    QString summary() const;
    void rebuildChart();
    void onChartClick(vtkObject*, unsigned long, void* callData);
    double yOf(const lc::ReportRow& r) const;
    // One chart series: total ms against yOf() of the given report rows.
    vtkPlot* addSeries(int plotType, const std::string& name, const std::vector<std::size_t>& rowIndices);

    Document* doc_;
    CullService* service_;
    lc::ReportOptions options_;
    QComboBox* backendBox_ = nullptr;
    QComboBox* yBox_ = nullptr;
    QSpinBox* repeatBox_ = nullptr;
    QPushButton* runButton_ = nullptr;
    QPushButton* cancelButton_ = nullptr;
    QProgressBar* progress_ = nullptr;
    QLabel* status_ = nullptr;
    QLabel* queue_ = nullptr;
    std::vector<std::unique_ptr<ParamControl>> params_;
    QVTKOpenGLNativeWidget* chartWidget_ = nullptr;
    vtkSmartPointer<vtkContextView> view_;
    vtkSmartPointer<vtkChartXY> chart_;
    // Plot series -> report rows, in the order points were added.
    std::map<std::string, std::vector<std::size_t>> seriesRows_;
    std::shared_ptr<lc::Report> report_;
    std::shared_ptr<lc::CancelToken> cancel_; // the running sweep's
    std::shared_ptr<Gate> gate_; // set while the worker may wait at it
    bool running_ = false;
    // Sweeps cancelled because another scene was opened: a sweep that
    // finishes with a count other than the one it started under is dropped.
    int sweepsDropped_ = 0;

    // Pace: seconds a configuration per backend, measured by the last sweep
    // (between progress reports, prompts excluded), under paceKey_.
    std::map<std::string, double> pace_;
    QString paceKey_;
    // The running sweep's clock and measured time per backend.
    QElapsedTimer clock_;
    qint64 lastProgressMs_ = 0, activeMs_ = 0;
    std::map<std::string, std::pair<qint64, int>> runPace_;
    QString runPaceKey_;
    // A loaded row whose run has not been shown yet (-1: none).
    int loadedRow_ = -1;
};

} // namespace lcui
