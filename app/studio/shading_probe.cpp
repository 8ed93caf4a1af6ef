#include "shading_probe.hpp"

#include "views/camera_view.hpp"
#include "work/cull_worker.hpp"
#include "document/document.hpp"
#include "window/main_window.hpp"
#include "probe_stats.hpp"

#include "culling/core/pipeline.hpp"

#include <QAction>
#include <QTimer>

#include <algorithm>

namespace {
double maxOf(const std::vector<double>& v) { return v.empty() ? 0 : *std::max_element(v.begin(), v.end()); }
} // namespace

ShadingProbe::ShadingProbe(lcui::MainWindow* window, int rounds) : QObject(window), window_(window), rounds_(rounds) {
    connect(window_, &lcui::MainWindow::runFinished, this, &ShadingProbe::onFinished);
}

void ShadingProbe::start() {
    clock_.start();
    started_ = true;
    previousMode_ = lcui::CameraView::toString(window_->cameraView()->imageMode());
    // The first pictures (of the opening run) come before any round: they
    // have no earlier run to keep an image from.
    generation_ = window_->cullService()->lastGeneration();
    const auto run = window_->document()->runs().runOutput();
    if (run && !run->shadedAll.empty() && window_->document()->runs().runGeneration() == generation_) {
        QTimer::singleShot(200, this, &ShadingProbe::nextRound); // shaded with the run already
        return;
    }
    window_->action("actionImage_heat")->trigger(); // so that Difference asks for the pictures
    window_->action("actionImage_difference")->trigger();
}

void ShadingProbe::nextRound() {
    if (round_ >= rounds_) {
        finish();
        return;
    }
    lcui::Document* doc = window_->document();
    listsAtMs_ = -1;
    if (round_ % 2 == 0) {
        // A light moved a little, as one step of a drag sends it.
        const int light = int(doc->scene().lights.size() / 2);
        const glm::dvec3 p = doc->scene().lights[std::size_t(light)].position;
        doc->moveLight(light, p + glm::dvec3(0.05, 0.0, 0.0), doc->newDragId());
        generation_ = window_->runCulling(/*liveEdit=*/true);
    } else {
        const bool clustered = doc->runs().settings().algorithm == lc::Algorithm::Clustered;
        window_->setParamFromUi("algorithm", clustered ? "2.5d" : "clustered");
        generation_ = window_->runCulling();
    }
}

void ShadingProbe::onFinished(quint64 generation) {
    if (!started_ || generation != generation_) return;
    const auto run = window_->document()->runs().runOutput();
    if (!run) return;
    const double now = clock_.nsecsElapsed() * 1e-6;
    if (run->shadedAll.empty()) {
        if (listsAtMs_ < 0) listsAtMs_ = now; // the lists, before their truth and pictures
        return;
    }
    // The camera view renders on the event loop's next turn (as Live drag's
    // probe measures): time the pictures once they are on screen.
    QTimer::singleShot(0, this, [this, run] {
        const double shown = clock_.nsecsElapsed() * 1e-6;
        if (listsAtMs_ >= 0 && round_ < rounds_) {
            const double ms = shown - listsAtMs_;
            culledShade_.push_back(run->result.timings.shadeMs);
            if (round_ % 2 == 0) {
                light_.push_back(ms);
                report_.allLightsUpdatedOnEveryLightRound &= run->allLightsUpdate.has_value();
            } else {
                algorithm_.push_back(ms);
                report_.allLightsKeptOnEveryAlgorithmRound &= run->allLightsReused;
            }
            ++round_;
        }
        // The opening run's pictures start the first round.
        QTimer::singleShot(200, this, &ShadingProbe::nextRound);
    });
}

void ShadingProbe::finish() {
    // The user's own camera image mode again (the window remembers it).
    window_->action(QString("actionImage_%1").arg(previousMode_))->trigger();
    ShadingReport r = report_;
    r.lightRounds = int(light_.size());
    r.algorithmRounds = int(algorithm_.size());
    r.lightMedianMs = median(light_);
    r.algorithmMedianMs = median(algorithm_);
    r.lightMaxMs = maxOf(light_);
    r.algorithmMaxMs = maxOf(algorithm_);
    r.medianCulledShadeMs = median(culledShade_);
    emit done(r);
}
