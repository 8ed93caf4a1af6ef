// The Report dock's chart: one series per algorithm and backend with its
// Pareto front, tooltips naming each point's configuration, and a click that
// loads a point's configuration into the document (report_dock.hpp).
#include "panels/report_dock.hpp"

#include "document/document.hpp"

#include "culling/core/backend.hpp"
#include "culling/core/errors.hpp"
#include "culling/core/pipeline.hpp"

#include <QComboBox>
#include <QEvent>
#include <QHBoxLayout>
#include <QLabel>
#include <QLocale>
#include <QMenu>
#include <QMessageBox>
#include <QMouseEvent>
#include <QProgressBar>
#include <QPushButton>
#include <QSpinBox>
#include <QToolButton>
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
#include <vtkStringArray.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>
#include <vtkTooltipItem.h>

#include <algorithm>
#include <cmath>

namespace lcui {

QString ReportDock::summary() const {
    if (!report_) return {};
    const lc::ReportRow* fastest = nullptr;
    for (const lc::ReportRow& r : report_->rows)
        if (r.falseNegatives == 0 && r.totalMs > 0 && (!fastest || r.totalMs < fastest->totalMs)) fastest = &r;
    QString s = fastest ? tr("Fastest without false negatives: %1 on %2, %3 ms (efficiency %4).")
                              .arg(QString::fromStdString(fastest->config.label()),
                                   QString::fromStdString(fastest->config.backend))
                              .arg(fastest->totalMs, 0, 'f', 3)
                              .arg(fastest->efficiency, 0, 'f', 3)
                        : tr("Every configuration misses lights.");
    return s + tr(" Click a point to load and run it.");
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
    // Hovering a point names its configuration, not just its numbers.
    vtkNew<vtkStringArray> labels;
    for (std::size_t row : rowIndices) labels->InsertNextValue(tooltipOf(row).toStdString());
    plot->SetIndexedLabels(labels);
    plot->SetTooltipLabelFormat("%i");
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
    const auto& rows = report_->rows;
    std::string title = report_->sceneName + ", " + std::to_string(report_->width) + "x" +
                        std::to_string(report_->height) + ", " + std::to_string(report_->lights) + " lights";
    if (report_->cancelled)
        title += " (partial: cancelled after " + std::to_string(rows.size()) + " of " +
                 std::to_string(report_->queued) + ")";
    chart_->SetTitle(title);
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
    // The row's settings; where a parameter does not change what the row
    // computes (the spot test of a scene without spot lights, the bins of
    // another algorithm), the user's own value stays.
    lc::CullSettings s = cfg.settings;
    const lc::CullSettings& mine = doc_->runs().settings();
    lc::Camera scratch = doc_->scene().camera;
    const bool spots = doc_->scene().hasSpotLights();
    for (const lc::ParamSpec& p : lc::cullParams())
        if (p.name != "tile" && p.name != "width" && p.name != "height" &&
            !lc::paramAppliesTo(p.name, cfg.settings, spots))
            lc::setParam(s, scratch, p.name, lc::getParam(mine, scratch, p.name));
    doc_->runs().setSettings(s);
    if (doc_->scene().camera.tileSize != cfg.tileSize) {
        lc::Camera cam = doc_->scene().camera;
        cam.tileSize = cfg.tileSize;
        doc_->setCamera(cam, tr("Set tile size (from the report)"));
    }
    loadedRow_ = int(row);
    status_->setText(tr("Loaded %1 (%2): culling it...").arg(QString::fromStdString(cfg.label()),
                                                            QString::fromStdString(cfg.backend)));
    emit configurationLoaded(int(row));
    // Loading alone would leave the previous run on screen as if it were
    // this configuration's.
    emit cullRequested(QString::fromStdString(cfg.backend));
}

void ReportDock::onRunOutput() {
    if (!report_ || loadedRow_ < 0 || std::size_t(loadedRow_) >= report_->rows.size()) return;
    const auto run = doc_->runs().runOutput();
    if (!run) return;
    // Is the run the loaded configuration's? Every parameter the row names.
    const lc::ReportRow& r = report_->rows[std::size_t(loadedRow_)];
    lc::Camera cam;
    cam.tileSize = run->result.grid.tileSize;
    for (const auto& [name, value] : r.config.params)
        if (!value.empty() && lc::getParam(run->result.settings, cam, name) != value) return;
    status_->setText(tr("Showing %1: the views show its run (false negatives %2, efficiency %3; in the report %4, "
                        "%5).")
                         .arg(QString::fromStdString(r.config.label()))
                         .arg(run->truthComputed ? QString::number(run->truth.metrics.falseNegatives) : tr("not yet"))
                         .arg(run->truthComputed ? QString::number(run->truth.metrics.efficiency, 'f', 3) : tr("not yet"))
                         .arg(r.falseNegatives)
                         .arg(r.efficiency, 0, 'f', 3));
    if (run->truthComputed) loadedRow_ = -1;
}

QString ReportDock::tooltipOf(std::size_t row) const {
    if (!report_ || row >= report_->rows.size()) return {};
    const lc::ReportRow& r = report_->rows[row];
    return tr("%1 (%2)\ntotal %3 ms = cull %4 + shade %5\nefficiency %6, false negatives %7, image RMSE %8")
        .arg(QString::fromStdString(r.config.label()), QString::fromStdString(r.config.backend))
        .arg(r.totalMs, 0, 'f', 3)
        .arg(r.cullMs, 0, 'f', 3)
        .arg(r.shadeMs, 0, 'f', 3)
        .arg(r.efficiency, 0, 'f', 3)
        .arg(r.falseNegatives)
        .arg(r.imageRmse, 0, 'g', 3);
}

QString ReportDock::chartTooltip() const { return QString::fromStdString(chart_->GetTooltip()->GetText()); }
bool ReportDock::chartTooltipVisible() const { return chart_->GetTooltip()->GetVisible(); }
QString ReportDock::chartTitle() const { return QString::fromStdString(chart_->GetTitle()); }

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
