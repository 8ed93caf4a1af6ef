#include "window/image_modes.hpp"

#include "document/document.hpp"
#include "views/camera_view.hpp"
#include "widgets/status_progress.hpp"
#include "work/cull_worker.hpp"

#include <QAction>
#include <QActionGroup>
#include <QMenu>
#include <QSettings>

#include <map>

namespace lcui {

namespace {
constexpr const char* kImageModeKey = "cameraView/imageMode";
}

ImageModes::ImageModes(Document* doc, CullService* service, CameraView* camera, StatusProgress* progress,
                       QMenu* view, QObject* parent)
    : QObject(parent) {
    using Mode = CameraView::ImageMode;
    QMenu* menu = view->addMenu(tr("Camera &image"));
    auto* group = new QActionGroup(menu);
    const std::pair<QString, Mode> modes[] = {{tr("Scene and heat map"), Mode::Heat},
                                              {tr("Shaded (culled lists)"), Mode::ShadedCulled},
                                              {tr("Shaded (all lights)"), Mode::ShadedAll},
                                              {tr("Difference |culled - all|"), Mode::Difference}};
    auto actions = std::make_shared<std::map<Mode, QAction*>>();
    int key = 1;
    for (const auto& [text, mode] : modes) {
        QAction* a = menu->addAction(text);
        a->setObjectName(QString("actionImage_%1").arg(CameraView::toString(mode)));
        a->setCheckable(true);
        a->setShortcut(QKeySequence(QString("Alt+%1").arg(key++)));
        group->addAction(a);
        (*actions)[mode] = a;
        const Mode m = mode;
        connect(a, &QAction::triggered, camera, [camera, m] { camera->setImageMode(m); });
    }

    // "shading..." with its progress and a Cancel in the status bar: shown
    // at once, as the images are what the user switched the view for.
    connect(service, &CullService::shadingStarted, this, [service, progress] {
        progress->begin("shading", tr("shading..."), [service] { service->worker()->cancelShading(); }, 0);
        progress->setProgress("shading", 0.0);
    });
    connect(service, &CullService::shadingProgress, this,
            [progress](quint64, double fraction) { progress->setProgress("shading", fraction); });
    connect(service, &CullService::shadingEnded, this, [progress] { progress->end("shading"); });

    connect(camera, &CameraView::imageModeChanged, this, [doc, service, actions](Mode mode) {
        (*actions)[mode]->setChecked(true);
        QSettings().setValue(kImageModeKey, CameraView::toString(mode));
        // The newest run (queued, running or shown) brings its images.
        const auto run = doc->runs().runOutput();
        if (CameraView::needsShading(mode) && service->lastGeneration() > 0 &&
            !(run && !run->shadedAll.empty() && doc->runs().runGeneration() == service->lastGeneration()))
            service->requestShading(service->lastGeneration());
    });

    Mode mode = Mode::Heat;
    CameraView::fromString(QSettings().value(kImageModeKey).toString(), &mode);
    camera->setImageMode(mode);
    (*actions)[camera->imageMode()]->setChecked(true);
}

} // namespace lcui
