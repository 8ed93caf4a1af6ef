#pragma once
// The Report dock: the speed-against-error sweep of culling/diagnostics/report.hpp on the
// document's scene, run on its own thread (its own backends: a Vulkan sweep
// opens its own device, so the culling worker is never blocked) with a
// progress bar and cancel, plotted with VTK charts (total time against
// efficiency or image error, one series per algorithm, the Pareto front as a
// line). Clicking a point loads that configuration into the document's
// culling settings (and its tile size into the camera, one undo step).

#include "culling/core/depth.hpp"
#include "culling/diagnostics/report.hpp"

#include <QWidget>

#include <map>
#include <memory>
#include <optional>
#include <thread>

#include <vtkChartXY.h>
#include <vtkContextView.h>
#include <vtkSmartPointer.h>

class QComboBox;
class QLabel;
class QProgressBar;
class QPushButton;
class QSpinBox;
class QVTKOpenGLNativeWidget;
class vtkObject;
class vtkPlot;

namespace lcui {

class Document;

class ReportDock : public QWidget {
    Q_OBJECT
public:
    explicit ReportDock(Document* doc, QWidget* parent = nullptr);
    ~ReportDock() override; // cancels and joins a running sweep

    // What start() sweeps; the controls fill backends/fixed algorithm/repeat,
    // tests may narrow it further.
    lc::ReportOptions& options() { return options_; }
    // Starts a sweep of a copy of the document's scene; false while one runs.
    bool start();
    void cancel();
    bool isRunning() const { return running_; }
    // The last finished report, or null.
    const lc::Report* report() const { return report_.get(); }
    // Loads row `row` of the report into the document (settings and tile size).
    void loadRow(std::size_t row);

    // --- for tests --------------------------------------------------------------
    QVTKOpenGLNativeWidget* chartWidget() const { return chartWidget_; }
    QProgressBar* progressBar() const { return progress_; }
    // Where row `row` is drawn in chartWidget(), in widget (logical) pixels;
    // nothing when the row is not plotted.
    std::optional<QPoint> chartPositionOf(std::size_t row) const;

signals:
    void started();
    // A configuration of the sweep finished (the status bar mirrors the dock's bar).
    void progressed(int done, int total, const QString& label);
    void finished(bool ok); // ok: a report was made (false: cancelled or failed)
    void configurationLoaded(int row);

private:
    void onProgress(int done, int total, const QString& label);
    // sceneGone: the sweep was of a scene another one replaced (nothing shown).
    void onDone(std::shared_ptr<lc::Report> report, const QString& error, bool cancelled, bool sceneGone);
    void rebuildChart();
    void onChartClick(vtkObject*, unsigned long, void* callData);
    double yOf(const lc::ReportRow& r) const;
    // One chart series: total ms against yOf() of the given report rows.
    vtkPlot* addSeries(int plotType, const std::string& name, const std::vector<std::size_t>& rowIndices);

    Document* doc_;
    lc::ReportOptions options_;
    QComboBox* backendBox_ = nullptr;
    QComboBox* algorithmBox_ = nullptr;
    QComboBox* yBox_ = nullptr;
    QSpinBox* repeatBox_ = nullptr;
    QPushButton* runButton_ = nullptr;
    QPushButton* cancelButton_ = nullptr;
    QProgressBar* progress_ = nullptr;
    QLabel* status_ = nullptr;
    QVTKOpenGLNativeWidget* chartWidget_ = nullptr;
    vtkSmartPointer<vtkContextView> view_;
    vtkSmartPointer<vtkChartXY> chart_;
    // Plot series -> report rows, in the order points were added.
    std::map<std::string, std::vector<std::size_t>> seriesRows_;
    std::shared_ptr<lc::Report> report_;
    std::thread thread_;
    lc::CancelToken cancel_;
    bool running_ = false;
    // Sweeps cancelled because another scene was opened: a sweep that
    // finishes with a count other than the one it started under is dropped.
    int sweepsDropped_ = 0;
};

} // namespace lcui
