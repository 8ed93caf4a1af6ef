#include "live_drag_probe.hpp"

#include "cull_worker.hpp"
#include "document.hpp"
#include "inspector_view.hpp"
#include "main_window.hpp"

#include "culling/pipeline.hpp"

#include <vtkCommand.h>
#include <vtkHandleWidget.h>
#include <vtkPointHandleRepresentation3D.h>

#include <algorithm>
#include <cmath>

namespace {
double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
} // namespace

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
    doc->setSelectedLights({light_});
    window_->setLive(true);
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
    window_->inspectorView()->handleRepresentation()->SetWorldPosition(wp);
    window_->inspectorView()->handleWidget()->InvokeEvent(vtkCommand::InteractionEvent);
    ++edits_;
    if (firstEditMs_ < 0) firstEditMs_ = now;
    // Live mode posted a request for this edit: its generation is the newest.
    editAtMs_[window_->cullService()->lastGeneration()] = now;
}

void LiveDragProbe::onFinished(quint64 generation) {
    if (firstEditMs_ < 0) return; // a run from before the drag
    if (const auto run = window_->document()->runOutput(); run && run->truthComputed)
        truth_.push_back(run->result.timings.groundTruthMs);
    const auto it = editAtMs_.find(generation);
    if (it == editAtMs_.end()) return;
    const double editAt = it->second;
    editAtMs_.erase(it); // the same generation's ground truth may follow: count it once
    if (const auto run = window_->document()->runOutput()) {
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
    emit done(r);
}
