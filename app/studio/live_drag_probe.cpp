#include "live_drag_probe.hpp"

#include "views/camera_view.hpp"
#include "work/cull_worker.hpp"
#include "document/document.hpp"
#include "views/inspector_view.hpp"
#include "window/main_window.hpp"
#include "probe_stats.hpp"

#include "culling/core/pipeline.hpp"

#include <vtkCommand.h>
#include <vtkHandleWidget.h>
#include <vtkPointHandleRepresentation3D.h>
#include <vtkRenderWindow.h>

#include <algorithm>
#include <cmath>


LiveDragProbe::LiveDragProbe(lcui::MainWindow* window, double seconds, double motionHz)
    : QObject(window), window_(window), seconds_(seconds) {
    motion_.setInterval(int(std::lround(1000.0 / motionHz)));
    connect(&motion_, &QTimer::timeout, this, &LiveDragProbe::step);
    connect(window_, &lcui::MainWindow::runFinished, this, &LiveDragProbe::onFinished);
}

void LiveDragProbe::start() {
    lcui::Document* doc = window_->document();
    // The light nearest the middle of the list: any light would do, this one
    // is deterministic for a given scene and seed.
    light_ = int(doc->scene().lights.size() / 2);
    doc->selection().setSelectedLights({light_});
    // Each view's frame on its own, before anything moves.
    std::vector<double> iv, cv;
    for (int i = 0; i < 3; ++i) {
        QElapsedTimer t;
        t.start();
        window_->inspectorView()->renderNow();
        iv.push_back(t.nsecsElapsed() * 1e-6);
        t.restart();
        window_->cameraView()->renderNow();
        cv.push_back(t.nsecsElapsed() * 1e-6);
    }
    staticInspectorMs_ = median(iv);
    staticCameraMs_ = median(cv);
    window_->setLive(true);
    // Render times of both views, from the render window's own start/end.
    vtkRenderWindow* iw = window_->inspectorView()->renderWindow();
    iw->AddObserver(vtkCommand::StartEvent, this, &LiveDragProbe::onInspectorStart);
    iw->AddObserver(vtkCommand::EndEvent, this, &LiveDragProbe::onInspectorEnd);
    vtkRenderWindow* cw = window_->cameraView()->renderWindow();
    cw->AddObserver(vtkCommand::StartEvent, this, &LiveDragProbe::onCameraStart);
    cw->AddObserver(vtkCommand::EndEvent, this, &LiveDragProbe::onCameraEnd);
    window_->inspectorView()->handleWidget()->InvokeEvent(vtkCommand::StartInteractionEvent);
    clock_.start();
    motion_.start();
}

void LiveDragProbe::step() {
    const double now = clock_.nsecsElapsed() * 1e-6;
    if (now > seconds_ * 1000.0) {
        finish();
        return;
    }
    lcui::Document* doc = window_->document();
    const glm::dvec3 p0 = doc->scene().lights[std::size_t(light_)].position;
    // A slow circle in the horizontal plane, like a hand moving a light.
    const double a = 0.002 * now;
    const glm::dvec3 p = p0 + glm::dvec3(0.05 * std::cos(a), 0.0, 0.05 * std::sin(a));
    double wp[3] = {p.x, p.y, p.z};
    QElapsedTimer edit;
    edit.start();
    window_->inspectorView()->handleRepresentation()->SetWorldPosition(wp);
    window_->inspectorView()->handleWidget()->InvokeEvent(vtkCommand::InteractionEvent);
    edit_.push_back(edit.nsecsElapsed() * 1e-6);
    ++edits_;
    if (firstEditMs_ < 0) firstEditMs_ = now;
    // Live mode posted a request for this edit: its generation is the newest.
    editAtMs_[window_->cullService()->lastGeneration()] = now;
}

void LiveDragProbe::onFinished(quint64 generation) {
    if (firstEditMs_ < 0) return; // a run from before the drag
    if (const auto run = window_->document()->runs().runOutput(); run && run->truthComputed)
        truth_.push_back(run->result.timings.groundTruthMs);
    const auto it = editAtMs_.find(generation);
    if (it == editAtMs_.end()) return;
    const double editAt = it->second;
    editAtMs_.erase(it); // the same generation's ground truth may follow: count it once
    if (const auto run = window_->document()->runs().runOutput()) {
        cull_.push_back(run->result.timings.cullMs);
        depth_.push_back(run->result.timings.depthMs);
    }
    // The views render on the event loop's next turn (scheduleRender): their
    // timers were queued before this one, so this fires after the redraw.
    QTimer::singleShot(0, this, [this, editAt] {
        const double now = clock_.nsecsElapsed() * 1e-6;
        latencies_.push_back(now - editAt);
        lastShownMs_ = now;
    });
}

void LiveDragProbe::onInspectorEnd() {
    if (firstEditMs_ >= 0 && inspectorClock_.isValid()) inspector_.push_back(inspectorClock_.nsecsElapsed() * 1e-6);
}

void LiveDragProbe::onCameraEnd() {
    if (firstEditMs_ >= 0 && cameraClock_.isValid()) camera_.push_back(cameraClock_.nsecsElapsed() * 1e-6);
}

void LiveDragProbe::finish() {
    if (stopping_) return;
    stopping_ = true;
    motion_.stop();
    window_->inspectorView()->handleWidget()->InvokeEvent(vtkCommand::EndInteractionEvent);
    LiveDragReport r;
    r.edits = edits_;
    r.shown = int(latencies_.size());
    r.seconds = std::max(0.0, lastShownMs_ - firstEditMs_) * 1e-3;
    r.medianLatencyMs = median(latencies_);
    r.maxLatencyMs = latencies_.empty() ? 0 : *std::max_element(latencies_.begin(), latencies_.end());
    r.medianCullMs = median(cull_);
    r.medianDepthMs = median(depth_);
    r.medianTruthMs = median(truth_);
    r.truths = int(truth_.size());
    r.medianEditMs = median(edit_);
    r.staticInspectorMs = staticInspectorMs_;
    r.staticCameraMs = staticCameraMs_;
    r.medianInspectorMs = median(inspector_);
    r.medianCameraMs = median(camera_);
    r.inspectorFrames = int(inspector_.size());
    r.cameraFrames = int(camera_.size());
    r.lights = window_->document()->scene().lights.size();
    r.inspectorWidth = window_->inspectorView()->width();
    r.inspectorHeight = window_->inspectorView()->height();
    emit done(r);
}
