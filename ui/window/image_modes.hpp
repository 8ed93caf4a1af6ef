#pragma once
// View > Camera image: the camera view's image modes (heat map, shaded with
// the culled lists, shaded with every light, their difference), kept in the
// settings, and the "shading..." progress with its Cancel in the status bar
// while the worker shades a run for them.

#include <QObject>

class QMenu;

namespace lcui {

class CameraView;
class CullService;
class Document;
class StatusProgress;

class ImageModes : public QObject {
    Q_OBJECT
public:
    // Adds the menu to `view` and restores the saved mode.
    ImageModes(Document* doc, CullService* service, CameraView* camera, StatusProgress* progress, QMenu* view,
               QObject* parent);
};

} // namespace lcui
