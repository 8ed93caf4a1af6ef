#pragma once
// New lights from the window's actions: one placed under the cursor in the
// inspector (Edit > Add light, Add spot light), many generated (Edit >
// Generate lights..., with progress and Cancel), each named uniquely beside
// the scene's lights, each addition one undo step.

#include "culling/scene/scene.hpp"

#include <QObject>
#include <QPoint>

class QWidget;

namespace lc {
struct LightGenSettings;
}

namespace lcui {

class Document;
class InspectorView;
class MessageLog;
class StatusProgress;
struct Prompts;

class LightPlacement : public QObject {
    Q_OBJECT
public:
    // `window`: the dialogs' parent; `prompts` outlives this object.
    LightPlacement(Document* doc, InspectorView* inspector, StatusProgress* progress, MessageLog* log,
                   const Prompts& prompts, QWidget* window);

    // Adds a light under the inspector position `pos` (logical px) when a
    // surface is there, else at the scene centre. Returns its index. A spot
    // light stands off the surface and points back at it (30 degrees).
    int addAt(const QPoint& inspectorPos, lc::LightKind kind = lc::LightKind::Point);
    // Generates lights as one undo step (progress + cancel for large counts).
    bool generate(const lc::LightGenSettings& settings);

private:
    Document* doc_;
    InspectorView* inspector_;
    StatusProgress* progress_;
    MessageLog* log_;
    const Prompts& prompts_;
    QWidget* window_;
};

} // namespace lcui
