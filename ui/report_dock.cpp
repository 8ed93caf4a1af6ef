#include "report_dock.hpp"

#include "document.hpp"

#include "culling/core/backend.hpp"
#include "culling/core/errors.hpp"

#include <QComboBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QSpinBox>
#include <QVBoxLayout>
#include <QVTKOpenGLNativeWidget.h>

#include <vtkAxis.h>
#include <vtkChartXY.h>
#include <vtkCommand.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <cmath>

namespace lcui {

ReportDock::ReportDock(Document* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
    auto* layout = new QVBoxLayout(this);
    auto* row = new QHBoxLayout;
    backendBox_ = new QComboBox;
    backendBox_->setObjectName("reportBackend");
    backendBox_->addItem(tr("every backend"), QString());
    for (const std::string& b : lc::availableBackends()) backendBox_->addItem(QString::fromStdString(b), QString::fromStdString(b));
    algorithmBox_ = new QComboBox;
    algorithmBox_->setObjectName("reportAlgorithm");
    algorithmBox_->addItem(tr("every algorithm"), QString());
    for (const std::string& a : lc::cullParam("algorithm").choices)
        algorithmBox_->addItem(QString::fromStdString(a), QString::fromStdString(a));
    repeatBox_ = new QSpinBox;
    repeatBox_->setObjectName("reportRepeat");
    repeatBox_->setRange(1, 50);
    repeatBox_->setValue(3);
    repeatBox_->setPrefix(tr("repeat "));
    yBox_ = new QComboBox;
    yBox_->setObjectName("reportYAxis");
    yBox_->addItem(tr("time vs efficiency"));
    yBox_->addItem(tr("time vs image error"));
    runButton_ = new QPushButton(tr("Run report"));
    runButton_->setObjectName("reportRun");
    cancelButton_ = new QPushButton(tr("Cancel"));
    cancelButton_->setObjectName("reportCancel");
    cancelButton_->setEnabled(false);
    row->addWidget(backendBox_);
    row->addWidget(algorithmBox_);
    row->addWidget(repeatBox_);
    row->addWidget(runButton_);
    row->addWidget(cancelButton_);
    row->addWidget(yBox_);
    row->addStretch(1);
    layout->addLayout(row);
    progress_ = new QProgressBar;
    progress_->setObjectName("reportProgress");
    progress_->setRange(0, 1);
    progress_->setValue(0);
    status_ = new QLabel(tr("Sweeps every culling configuration of the scene; click a point to load it."));
    status_->setObjectName("reportStatus");
    auto* row2 = new QHBoxLayout;
    row2->addWidget(progress_, 1);
    row2->addWidget(status_, 2);
    layout->addLayout(row2);

    chartWidget_ = new QVTKOpenGLNativeWidget;
    chartWidget_->setObjectName("reportChart");
    chartWidget_->setMinimumHeight(220);
    vtkNew<vtkGenericOpenGLRenderWindow> rw;
    chartWidget_->setRenderWindow(rw);
    view_ = vtkSmartPointer<vtkContextView>::New();
    view_->SetRenderWindow(rw);
    view_->SetInteractor(chartWidget_->interactor());
    view_->GetRenderer()->SetBackground(1.0, 1.0, 1.0);
    chart_ = vtkSmartPointer<vtkChartXY>::New();
    chart_->SetShowLegend(true);
    view_->GetScene()->AddItem(chart_);
    // Left click notifies (vtkChart::NOTIFY, the default) with the point's
    // series and index: that is the click-to-load.
    chart_->AddObserver(vtkCommand::InteractionEvent, this, &ReportDock::onChartClick);
    layout->addWidget(chartWidget_, 1);

    connect(runButton_, &QPushButton::clicked, this, [this] { start(); });
    connect(cancelButton_, &QPushButton::clicked, this, &ReportDock::cancel);
    connect(yBox_, qOverload<int>(&QComboBox::currentIndexChanged), this, [this] { rebuildChart(); });
    // A report describes the scene it swept: another scene (New, Open, a
    // built-in) drops it, and a sweep still running is cancelled and its
    // result never shown, so no click loads one scene's point into another.
    connect(doc_, &Document::sceneReset, this, [this] {
        if (running_) {
            cancel_.cancelled = true;
            ++sweepsDropped_;
        }
        if (!report_ && !running_) return;
        report_.reset();
        rebuildChart();
        progress_->setRange(0, 1);
        progress_->setValue(0);
        status_->setText(tr("Another scene was opened: run the report for it."));
    });
    rebuildChart();
}

ReportDock::~ReportDock() {
    cancel_.cancelled = true;
    if (thread_.joinable()) thread_.join();
}

bool ReportDock::start() {
    if (running_) return false;
    if (thread_.joinable()) thread_.join();
    options_.backends.clear();
    if (const QString b = backendBox_->currentData().toString(); !b.isEmpty()) options_.backends = {b.toStdString()};
    if (const QString a = algorithmBox_->currentData().toString(); !a.isEmpty())
        options_.fixed["algorithm"] = a.toStdString();
    else
        options_.fixed.erase("algorithm");
    options_.repeat = repeatBox_->value();
    cancel_.cancelled = false;
    running_ = true;
    runButton_->setEnabled(false);
    cancelButton_->setEnabled(true);
    progress_->setRange(0, 0); // busy until the first progress report
    status_->setText(tr("Opening backends..."));
    emit started();
    const lc::Scene scene = doc_->scene();
    const lc::ReportOptions options = options_;
    const int dropped = sweepsDropped_;
    thread_ = std::thread([this, scene, options, dropped] {
        std::shared_ptr<lc::Report> rep;
        QString error;
        bool cancelled = false;
        try {
            auto progress = [this, dropped](std::size_t done, std::size_t total, const std::string& label) {
                const QString text = QString::fromStdString(label);
                QMetaObject::invokeMethod(
                    this,
                    [this, done, total, text, dropped] {
                        if (dropped == sweepsDropped_) onProgress(int(done), int(total), text);
                    },
                    Qt::QueuedConnection);
            };
            rep = std::make_shared<lc::Report>(lc::runReport(scene, options, progress, &cancel_));
        } catch (const lc::Cancelled&) {
            cancelled = true;
        } catch (const std::exception& e) {
            error = QString::fromStdString(e.what());
        }
        QMetaObject::invokeMethod(
            this,
            [this, rep, error, cancelled, dropped] {
                // Of a scene no longer open: finish the sweep, show nothing of it.
                const bool sceneGone = dropped != sweepsDropped_;
                onDone(sceneGone ? nullptr : rep, error, cancelled || sceneGone, sceneGone);
            },
            Qt::QueuedConnection);
    });
    return true;
}

void ReportDock::cancel() {
    if (!running_) return;
    cancel_.cancelled = true;
    status_->setText(tr("Cancelling..."));
}

void ReportDock::onProgress(int done, int total, const QString& label) {
    progress_->setRange(0, std::max(total, 1));
    progress_->setValue(done);
    status_->setText(tr("%1/%2 %3").arg(done).arg(total).arg(label));
    emit progressed(done, total, label);
}

void ReportDock::onDone(std::shared_ptr<lc::Report> report, const QString& error, bool cancelled, bool sceneGone) {
    if (thread_.joinable()) thread_.join();
    running_ = false;
    runButton_->setEnabled(true);
    cancelButton_->setEnabled(false);
    if (progress_->maximum() == 0) progress_->setRange(0, 1);
    if (report) {
        report_ = std::move(report);
        progress_->setValue(progress_->maximum());
        status_->setText(tr("%1 configurations; click a point to load it.").arg(report_->rows.size()));
        rebuildChart();
    } else {
        progress_->setValue(0);
        if (!sceneGone) // else the message of the scene's reset stays
            status_->setText(cancelled ? tr("Cancelled; the previous report is kept.") : tr("Failed: %1").arg(error));
    }
    emit finished(report_ != nullptr && !cancelled && error.isEmpty());
}

double ReportDock::yOf(const lc::ReportRow& r) const {
    return yBox_->currentIndex() == 0 ? r.efficiency : r.imageRmse;
}

vtkPlot* ReportDock::addSeries(int plotType, const std::string& name, const std::vector<std::size_t>& rowIndices) {
    const auto& rows = report_->rows;
    vtkNew<vtkTable> table;
    vtkNew<vtkDoubleArray> xs, ys;
    xs->SetName("total ms");
    ys->SetName(name.c_str());
    table->AddColumn(xs);
    table->AddColumn(ys);
    table->SetNumberOfRows(vtkIdType(rowIndices.size()));
    for (std::size_t k = 0; k < rowIndices.size(); ++k) {
        table->SetValue(vtkIdType(k), 0, rows[rowIndices[k]].totalMs);
        table->SetValue(vtkIdType(k), 1, yOf(rows[rowIndices[k]]));
    }
    vtkPlot* plot = chart_->AddPlot(plotType);
    plot->SetInputData(table, 0, 1);
    plot->SetLabel(name);
    return plot;
}

void ReportDock::rebuildChart() {
    chart_->ClearPlots();
    seriesRows_.clear();
    const bool efficiency = yBox_->currentIndex() == 0;
    chart_->GetAxis(vtkAxis::LEFT)->SetTitle(efficiency ? "efficiency E/W" : "image RMSE");
    chart_->GetAxis(vtkAxis::BOTTOM)->SetTitle("total ms (cull + shade)");
    if (!report_ || report_->rows.empty()) {
        chart_->SetTitle("no report yet");
        chartWidget_->renderWindow()->Render();
        return;
    }
    chart_->SetTitle(report_->sceneName + ", " + std::to_string(report_->width) + "x" +
                     std::to_string(report_->height) + ", " + std::to_string(report_->lights) + " lights");
    const auto& rows = report_->rows;
    double xmin = 1e300, xmax = 0;
    for (const lc::ReportRow& r : rows)
        if (r.totalMs > 0) xmin = std::min(xmin, r.totalMs), xmax = std::max(xmax, r.totalMs);
    const bool logX = xmax > 10 * xmin;
    // One point series per algorithm and backend (the second backend hollow:
    // circles instead of squares).
    const auto algorithms = lc::cullParam("algorithm").choices;
    for (std::size_t b = 0; b < report_->backendDevices.size(); ++b) {
        const std::string& backend = report_->backendDevices[b].first;
        for (std::size_t a = 0; a < algorithms.size(); ++a) {
            std::vector<std::size_t> members;
            for (std::size_t i = 0; i < rows.size(); ++i)
                if (rows[i].config.backend == backend && lc::toString(rows[i].config.settings.algorithm) == algorithms[a] &&
                    rows[i].totalMs > 0 && std::isfinite(yOf(rows[i])))
                    members.push_back(i);
            if (members.empty()) continue;
            const std::string name = algorithms[a] + " (" + backend + ")";
            vtkPlot* plot = addSeries(vtkChart::POINTS, name, members);
            const glm::dvec3 rgb = lc::algorithmColour(lc::algorithmFromString(algorithms[a])) * 255.0;
            plot->SetColor(static_cast<unsigned char>(rgb.r + 0.5), static_cast<unsigned char>(rgb.g + 0.5),
                           static_cast<unsigned char>(rgb.b + 0.5), 255);
            if (auto* pts = vtkPlotPoints::SafeDownCast(plot)) {
                pts->SetMarkerStyle(b == 0 ? vtkPlotPoints::SQUARE : vtkPlotPoints::CIRCLE);
                pts->SetMarkerSize(7);
            }
            seriesRows_[name] = std::move(members);
        }
        // The Pareto front of this backend, fastest first.
        std::vector<std::size_t> front;
        for (std::size_t i = 0; i < rows.size(); ++i)
            if (rows[i].config.backend == backend && rows[i].totalMs > 0 &&
                (efficiency ? rows[i].paretoEfficiency : rows[i].paretoError))
                front.push_back(i);
        std::sort(front.begin(), front.end(), [&](auto x, auto y) { return rows[x].totalMs < rows[y].totalMs; });
        if (front.size() >= 2) {
            const std::string name = "Pareto front (" + backend + ")";
            vtkPlot* line = addSeries(vtkChart::LINE, name, front);
            line->SetColor(217, 26, 26, 255);
            line->SetWidth(2.0);
            seriesRows_[name] = std::move(front);
        }
    }
    chart_->GetAxis(vtkAxis::BOTTOM)->SetLogScale(logX);
    chart_->RecalculateBounds();
    chartWidget_->renderWindow()->Render();
}

void ReportDock::onChartClick(vtkObject*, unsigned long, void* callData) {
    const auto* data = static_cast<const vtkChartPlotData*>(callData);
    if (!data || !report_) return;
    auto it = seriesRows_.find(data->SeriesName);
    if (it == seriesRows_.end() || data->Index < 0 || std::size_t(data->Index) >= it->second.size()) return;
    loadRow(it->second[std::size_t(data->Index)]);
}

void ReportDock::loadRow(std::size_t row) {
    if (!report_ || row >= report_->rows.size()) return;
    const lc::ReportConfig& cfg = report_->rows[row].config;
    doc_->setSettings(cfg.settings);
    if (doc_->scene().camera.tileSize != cfg.tileSize) {
        lc::Camera cam = doc_->scene().camera;
        cam.tileSize = cfg.tileSize;
        doc_->setCamera(cam, tr("Set tile size (from the report)"));
    }
    status_->setText(tr("Loaded %1 (%2)").arg(QString::fromStdString(cfg.label()), QString::fromStdString(cfg.backend)));
    emit configurationLoaded(int(row));
}

std::optional<QPoint> ReportDock::chartPositionOf(std::size_t row) const {
    if (!report_ || row >= report_->rows.size()) return std::nullopt;
    const lc::ReportRow& r = report_->rows[row];
    bool plotted = false;
    for (const auto& [name, members] : seriesRows_)
        if (name.rfind("Pareto", 0) != 0 && std::find(members.begin(), members.end(), row) != members.end())
            plotted = true;
    if (!plotted) return std::nullopt;
    // Axis ends in scene pixels (origin bottom-left, device pixels).
    vtkAxis* ax = chart_->GetAxis(vtkAxis::BOTTOM);
    vtkAxis* ay = chart_->GetAxis(vtkAxis::LEFT);
    const float* x1 = ax->GetPoint1();
    const float* x2 = ax->GetPoint2();
    const float* y1 = ay->GetPoint1();
    const float* y2 = ay->GetPoint2();
    auto axisT = [](vtkAxis* a, double v) {
        double lo = a->GetUnscaledMinimum(), hi = a->GetUnscaledMaximum();
        if (a->GetLogScaleActive()) lo = std::log10(lo), hi = std::log10(hi), v = std::log10(v);
        return (v - lo) / (hi - lo);
    };
    const double sx = x1[0] + axisT(ax, r.totalMs) * (x2[0] - x1[0]);
    const double sy = y1[1] + axisT(ay, yOf(r)) * (y2[1] - y1[1]);
    const double dpr = chartWidget_->devicePixelRatioF();
    const int h = chartWidget_->renderWindow()->GetSize()[1];
    return QPoint(int(std::lround(sx / dpr)), int(std::lround((h - sy) / dpr)));
}

} // namespace lcui
