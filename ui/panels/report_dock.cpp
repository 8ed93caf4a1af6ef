#include "panels/report_dock.hpp"
#include "panels/report_text.hpp"

#include "document/document.hpp"
#include "work/cull_worker.hpp"

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
#include <QPointer>
#include <QPushButton>
#include <QSpinBox>
#include <QToolButton>
#include <QVBoxLayout>
#include <QVTKOpenGLNativeWidget.h>

#include <vtkAxis.h>

#include <chrono>
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

using namespace reporttext;

ReportDock::ReportDock(Document* doc, CullService* service, QWidget* parent)
    : QWidget(parent), doc_(doc), service_(service) {
    confirm = [](QWidget* parent, const QString& title, const QString& text) {
        return QMessageBox::question(parent, title, text, QMessageBox::Yes | QMessageBox::No, QMessageBox::No) ==
               QMessageBox::Yes;
    };
    auto* layout = new QVBoxLayout(this);
    auto* row = new QHBoxLayout;
    backendBox_ = new QComboBox;
    backendBox_->setObjectName("reportBackend");
    backendBox_->addItem(tr("every backend"), QString());
    for (const std::string& b : lc::availableBackends()) backendBox_->addItem(QString::fromStdString(b), QString::fromStdString(b));
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
    row->addWidget(repeatBox_);
    row->addWidget(runButton_);
    row->addWidget(cancelButton_);
    row->addWidget(yBox_);
    row->addStretch(1);
    layout->addLayout(row);

    // One menu per swept parameter, from the parameter table: every value
    // the sweep would take, checked; unchecking holds the parameter at the
    // rest (ReportOptions::fixed, as the CLI's flags do). Int parameters
    // other than tile and cells keep their default in the sweep: no menu.
    auto* paramRow = new QHBoxLayout;
    paramRow->addWidget(new QLabel(tr("Sweep:")));
    auto asText = [](const std::vector<std::uint32_t>& v) {
        std::vector<std::string> s;
        for (auto x : v) s.push_back(std::to_string(x));
        return s;
    };
    for (const lc::ParamSpec& p : lc::cullParams()) {
        if (p.name == "tile")
            addParamControl(p, {"4", "8", "12", "16", "20", "24", "32", "48", "64"}, asText(options_.tileSizes));
        else if (p.name == "cells")
            addParamControl(p, {"1", "2", "4", "8", "16", "32"}, asText(options_.cellCounts));
        else if (p.type == lc::ParamType::Choice)
            addParamControl(p, p.choices, p.choices);
        else if (p.name == "conservative")
            addParamControl(p, {"false", "true"}, {"true"});
        else if (p.type == lc::ParamType::Bool)
            addParamControl(p, {"false", "true"}, {"false", "true"});
        else if (p.name == "proxy-level")
            addParamControl(p, {"0", "1", "2", "3", "4"}, {"0", "1", "2"});
        else if (p.name == "proxy-overfit")
            addParamControl(p, {"auto", "1", "1.1", "1.2"}, {"auto"});
    }
    for (const auto& c : params_) paramRow->addWidget(c->button);
    paramRow->addStretch(1);
    layout->addLayout(paramRow);

    queue_ = new QLabel;
    queue_->setObjectName("reportQueue");
    queue_->setWordWrap(true);
    layout->addWidget(queue_);
    progress_ = new QProgressBar;
    progress_->setObjectName("reportProgress");
    progress_->setRange(0, 1);
    progress_->setValue(0);
    // Counts, not a percentage: one configuration of thousands is 0%.
    progress_->setFormat(tr("%v of %m"));
    status_ = new QLabel(tr("Sweeps the culling configurations chosen above; click a point to load and run it."));
    status_->setObjectName("reportStatus");
    status_->setWordWrap(true);
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
    connect(backendBox_, qOverload<int>(&QComboBox::currentIndexChanged), this, &ReportDock::updateQueueLabel);
    connect(repeatBox_, qOverload<int>(&QSpinBox::valueChanged), this, &ReportDock::updateQueueLabel);
    // What changes the count (spot lights) or the pace (size, lights, meshes).
    connect(doc_, &Document::sceneEdited, this, &ReportDock::updateQueueLabel);
    connect(doc_, &Document::cameraChanged, this, &ReportDock::updateQueueLabel);
    connect(&doc_->runs(), &RunState::runOutputChanged, this, &ReportDock::onRunOutput);
    // A report describes the scene it swept: another scene (New, Open, a
    // built-in) drops it, and a sweep still running is cancelled and its
    // result never shown, so no click loads one scene's point into another.
    connect(doc_, &Document::sceneReset, this, [this] {
        loadedRow_ = -1;
        updateQueueLabel();
        if (running_) {
            stopSweep();
            ++sweepsDropped_;
        }
        if (!report_ && !running_) return;
        report_.reset();
        rebuildChart();
        progress_->setRange(0, 1);
        progress_->setValue(0);
        status_->setText(tr("Another scene was opened: run the report for it."));
    });
    updateQueueLabel();
    rebuildChart();
}

ReportDock::~ReportDock() { stopSweep(); }

void ReportDock::releaseGate() {
    if (!gate_) return;
    {
        std::lock_guard lock(gate_->mutex);
        gate_->open = true;
    }
    gate_->cv.notify_all();
    gate_.reset();
}

void ReportDock::stopSweep() {
    if (cancel_) cancel_->cancelled = true;
    releaseGate();
}

bool ReportDock::start() {
    if (running_) return false;
    std::size_t queued = 0;
    try {
        queued = queuedConfigurations();
    } catch (const std::exception& e) {
        status_->setText(tr("Failed: %1").arg(QString::fromStdString(e.what())));
        return false;
    }
    const std::optional<double> estimate = estimatedSeconds();
    if (estimate && *estimate > confirmAboveSeconds &&
        !confirm(this, tr("Run report"),
                 tr("This sweep queues %1 configurations: %2 (an estimate from the last run on this scene). "
                    "Run it?")
                     .arg(count(queued), aboutTime(*estimate)))) {
        status_->setText(tr("Not started: hold some parameters above to queue fewer configurations."));
        return false;
    }
    options_ = optionsFromControls();
    cancel_ = std::make_shared<lc::CancelToken>();
    // Without a pace the first configuration is the timing: the worker waits
    // after it until onProgress has estimated the rest.
    gate_ = !estimate && queued > 1 ? std::make_shared<Gate>() : nullptr;
    running_ = true;
    runButton_->setEnabled(false);
    cancelButton_->setEnabled(true);
    progress_->setRange(0, 0); // busy until the first configuration
    status_->setText(tr("Opening backends, depth pre-pass..."));
    runPace_.clear();
    runPaceKey_ = paceKey();
    activeMs_ = lastProgressMs_ = 0;
    clock_.start();
    emit started();
    const lc::Scene scene = doc_->scene();
    lc::ReportOptions options = options_;
    options.partialOnCancel = true;
    const int dropped = sweepsDropped_;
    // A job of the culling worker: its thread and backends (one device).
    // Between configurations it lets the culling requests that came run.
    QPointer<ReportDock> self(this);
    service_->runJob([self, scene, options, dropped, gate = gate_, cancel = cancel_](CullJobContext& job) mutable {
        std::shared_ptr<lc::Report> rep;
        QString error;
        bool cancelled = false;
        try {
            options.backendFor = [&job](const std::string& name) -> lc::CullBackend& { return job.backend(name); };
            auto progress = [self, dropped, gate, cancel, &job](std::size_t done, std::size_t total,
                                                                const std::string& label) {
                const QString text = QString::fromStdString(label);
                QMetaObject::invokeMethod(
                    self,
                    [self, done, total, text, dropped] {
                        if (self && dropped == self->sweepsDropped_) self->onProgress(int(done), int(total), text);
                    },
                    Qt::QueuedConnection);
                job.serve();
                // After the first configuration, until the dock has decided
                // whether to go on (culling requests still run meanwhile).
                if (gate && done == 1) {
                    std::unique_lock lock(gate->mutex);
                    while (!gate->open && !cancel->cancelled) {
                        lock.unlock();
                        job.serve();
                        lock.lock();
                        gate->cv.wait_for(lock, std::chrono::milliseconds(50));
                    }
                }
            };
            rep = std::make_shared<lc::Report>(lc::runReport(scene, options, progress, cancel.get()));
        } catch (const lc::Cancelled&) {
            cancelled = true;
        } catch (const std::exception& e) {
            error = QString::fromStdString(e.what());
        }
        QMetaObject::invokeMethod(
            self,
            [self, rep, error, cancelled, dropped] {
                if (!self) return;
                // Of a scene no longer open: finish the sweep, show nothing of it.
                const bool sceneGone = dropped != self->sweepsDropped_;
                self->onDone(sceneGone ? nullptr : rep, error, cancelled || sceneGone, sceneGone);
            },
            Qt::QueuedConnection);
    }, cancel_);
    return true;
}

void ReportDock::cancel() {
    if (!running_) return;
    stopSweep();
    status_->setText(tr("Cancelling..."));
}

void ReportDock::onProgress(int done, int total, const QString& label) {
    const qint64 now = clock_.elapsed();
    activeMs_ += now - lastProgressMs_;
    auto& [ms, n] = runPace_[label.section(' ', 0, 0).toStdString()]; // the label starts with the backend
    ms += now - lastProgressMs_;
    ++n;
    lastProgressMs_ = now;
    progress_->setRange(0, std::max(total, 1));
    progress_->setValue(done);
    const double left = double(activeMs_) / std::max(done, 1) * (total - done) / 1000.0;
    status_->setText(done < total ? tr("%1 left (at this run's pace); last: %2").arg(aboutTime(left), label)
                                  : tr("last: %1").arg(label));
    emit progressed(done, total, label);
    if (done == 1 && gate_) {
        // The first configuration timed: the estimate of the whole sweep.
        const double estimate = double(activeMs_) / 1000.0 * total;
        if (estimate > confirmAboveSeconds) {
            const bool go = confirm(
                this, tr("Run report"),
                tr("This sweep queues %1 configurations: %2 (an estimate from its first configuration, which took "
                   "%3 s). Go on? No keeps the one that finished.")
                    .arg(count(std::size_t(total)), aboutTime(estimate))
                    .arg(double(activeMs_) / 1000.0, 0, 'g', 2));
            if (!go) cancel_->cancelled = true;
            lastProgressMs_ = clock_.elapsed(); // the question's time is not the sweep's
        }
        releaseGate();
    }
}

void ReportDock::onDone(std::shared_ptr<lc::Report> report, const QString& error, bool cancelled, bool sceneGone) {
    gate_.reset();
    running_ = false;
    runButton_->setEnabled(true);
    cancelButton_->setEnabled(false);
    if (progress_->maximum() == 0) progress_->setRange(0, 1);
    // The pace of this sweep estimates the next one of the same scene.
    if (!sceneGone && !runPace_.empty()) {
        pace_.clear();
        for (const auto& [backend, msn] : runPace_) pace_[backend] = double(msn.first) / 1000.0 / msn.second;
        paceKey_ = runPaceKey_;
    }
    const bool partial = report && report->cancelled;
    if (report && !(partial && report->rows.empty())) {
        report_ = std::move(report);
        loadedRow_ = -1;
        rebuildChart();
        if (partial) {
            status_->setText(tr("Partial report: cancelled after %1 of %2 configurations. %3")
                                 .arg(report_->rows.size())
                                 .arg(report_->queued)
                                 .arg(summary()));
        } else {
            progress_->setValue(progress_->maximum());
            status_->setText(tr("%1 configurations in %2. %3")
                                 .arg(report_->rows.size())
                                 .arg(duration(clock_.elapsed() / 1000.0))
                                 .arg(summary()));
        }
    } else if (!sceneGone) { // else the message of the scene's reset stays
        progress_->setValue(0);
        status_->setText(partial || cancelled ? tr("Cancelled before a configuration finished; the previous report is kept.")
                                              : tr("Failed: %1").arg(error));
    }
    updateQueueLabel();
    emit finished(report_ != nullptr && !partial && !cancelled && error.isEmpty() && !sceneGone);
}

} // namespace lcui
