// MainWindow: the camera view's image modes (View > Camera image), the
// "shading..." status and the shaded run an export needs. Kept apart from
// main_window.cpp so that shading stays one small hook there.
#include "window/main_window.hpp"

#include "views/camera_view.hpp"
#include "work/cull_worker.hpp"
#include "document/document.hpp"
#include "widgets/status_progress.hpp"

#include <QAction>
#include <QActionGroup>
#include <QEventLoop>
#include <QMenu>
#include <QSettings>

namespace lcui {

namespace {
constexpr const char* kImageModeKey = "cameraView/imageMode";
}

void MainWindow::buildImageModes(QMenu* view) {
    using Mode = CameraView::ImageMode;
    QMenu* menu = view->addMenu(tr("Camera &image"));
    auto* group = new QActionGroup(this);
    const std::pair<QString, Mode> modes[] = {{tr("Scene and heat map"), Mode::Heat},
                                              {tr("Shaded (culled lists)"), Mode::ShadedCulled},
                                              {tr("Shaded (all lights)"), Mode::ShadedAll},
                                              {tr("Difference |culled - all|"), Mode::Difference}};
    int key = 1;
    for (const auto& [text, mode] : modes) {
        QAction* a = menu->addAction(text);
        a->setObjectName(QString("actionImage_%1").arg(CameraView::toString(mode)));
        a->setCheckable(true);
        a->setShortcut(QKeySequence(QString("Alt+%1").arg(key++)));
        group->addAction(a);
        const Mode m = mode;
        connect(a, &QAction::triggered, this, [this, m] { cameraView_->setImageMode(m); });
    }

    // "shading..." with its progress and a Cancel in the status bar: shown
    // at once, as the images are what the user switched the view for.
    connect(service_, &CullService::shadingStarted, this, [this] {
        statusProgress_->begin("shading", tr("shading..."), [this] { service_->worker()->cancelShading(); }, 0);
        statusProgress_->setProgress("shading", 0.0);
    });
    connect(service_, &CullService::shadingProgress, this, [this](quint64, double fraction) {
        statusProgress_->setProgress("shading", fraction);
    });
    connect(service_, &CullService::shadingEnded, this, [this] { statusProgress_->end("shading"); });

    connect(cameraView_, &CameraView::imageModeChanged, this, [this](Mode mode) {
        if (QAction* a = action(QString("actionImage_%1").arg(CameraView::toString(mode)))) a->setChecked(true);
        QSettings().setValue(kImageModeKey, CameraView::toString(mode));
        // The newest run (queued, running or shown) brings its images.
        const auto run = doc_->runOutput();
        if (CameraView::needsShading(mode) && service_->lastGeneration() > 0 &&
            !(run && !run->shadedAll.empty() && doc_->runGeneration() == service_->lastGeneration()))
            service_->requestShading(service_->lastGeneration());
    });

    Mode mode = Mode::Heat;
    CameraView::fromString(QSettings().value(kImageModeKey).toString(), &mode);
    cameraView_->setImageMode(mode);
    action(QString("actionImage_%1").arg(CameraView::toString(cameraView_->imageMode())))->setChecked(true);
}

std::shared_ptr<const lc::RunOutput> MainWindow::shadedRunOutput() {
    auto run = doc_->runOutput();
    if (!run || !run->shadedAll.empty()) return run;
    const quint64 generation = doc_->runGeneration();
    QEventLoop loop;
    bool ended = false;
    QString error;
    // finished() also reaches onRunFinished, which shows the images.
    auto c1 = connect(service_, &CullService::finished, &loop,
                      [&](quint64 g, std::shared_ptr<const lc::RunOutput> out) {
                          if (g != generation || out->shadedAll.empty()) return;
                          run = out;
                          ended = true;
                          loop.quit();
                      });
    auto c2 = connect(service_, &CullService::shadingEnded, &loop, [&](quint64 g, bool shaded) {
        if (g != generation || shaded) return;
        error = tr("the shading pass of run %1 did not finish (a newer run replaced it, or it failed)")
                    .arg(generation);
        ended = true;
        loop.quit();
    });
    service_->requestShading(generation);
    if (!ended) loop.exec(QEventLoop::ExcludeUserInputEvents);
    disconnect(c1);
    disconnect(c2);
    if (!error.isEmpty()) {
        log(error, true);
        return nullptr;
    }
    return run;
}

} // namespace lcui
